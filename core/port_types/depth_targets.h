// Port payload `depth_targets` (latest): the depth path's targets for the sheet model
// (plugins/depth_tracking -> plugins/sheet_model): per sheet point (a model node) the world
// position the registered point cloud puts it at and a weight from the cloud's support.
// The model pulls the sheet point along its own normal towards the target (a point-to-plane
// zero-length spring, seed 001 Eq. 4 projected on the normal: depth sees the surface, hardly
// where along it a point of a plain sheet lies). Geometry in mm, world frame; sheet (u, v) mm.
#pragma once

#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct DepthTargets {
  static constexpr char kPortType[] = "crease.DepthTargets";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kCapacity = 1024;
  struct Point {
    float world_mm[3];  // target, world frame
    float sheet_mm[2];  // (u, v) of the sheet point it is for
    float weight;       // (0, 1]: the spring's stiffness scale (CPD posterior support, capped)
  };
  std::int64_t timestamp_ns = 0;   // CLOCK_MONOTONIC capture time of the depth frame set
  std::uint64_t frame = 0;         // the depth source's frame index
  std::uint32_t count = 0;         // valid entries of points[]
  std::uint32_t cloud_points = 0;  // points the registration used (after voxels, thinning)
  std::uint32_t visible_nodes = 0; // model nodes some camera sees (the registration's centroids)
  std::uint32_t iterations = 0;    // CPD iterations of this frame
  float sigma2_mm2 = 0;            // CPD's final variance
  std::uint32_t cameras_ok = 0;    // bit k: depth camera k delivered depth
  Point points[kCapacity];
  // Non-finite entries are tolerated here: the model drops them one by one.
};

CREASE_PORT_PAYLOAD_LAYOUT(DepthTargets::Point, 24, 4);
CREASE_PORT_PAYLOAD_LAYOUT(DepthTargets, 24616, 8);

}  // namespace crease
