// Which of the sheet model's nodes each depth camera sees, from the model itself (seed 001's
// layer ambiguity: once a flap covers the lower layer, the cloud from above is the flap's, and
// the lower layer's nodes must not be pulled onto it). The model's grid triangles are rasterised
// per camera at 1/scale of its resolution into a depth buffer that keeps, per pixel, the grid
// cell of the nearest surface. A node is seen by a camera when it projects inside the image, in
// front of it, and the nearest surface at one of the 3 x 3 pixels around it is a grid cell at
// most `cells` steps from the node's own cells (its own layer there, not a layer lying over it:
// no depth tolerance, so layers a millimetre apart are told apart). With the cameras' depth images
// (set_depth_check), a node is also hidden from a camera whose measured surface around the node's
// pixel lies nearer than the node by more than `occluder_mm` everywhere: something the model does
// not know of (the real flap ahead of the model's, a hand) stands in front of it. configure()
// allocates; compute() allocates nothing and throws nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "plugins/camera_rig/camera_model.h"

namespace crease::depth {

class NodeVisibility {
 public:
  // Non-RT. nodes_u x nodes_v grid (row by row); scale >= 1; cells >= 0. Throws ConfigError.
  void configure(const std::vector<vision::Camera>& cameras, int nodes_u, int nodes_v, int scale, int cells);
  // Non-RT. depth_unit_mm: per camera, one count of its depth image; occluder_mm > 0: a node
  // with a measured surface nearer than itself by more than this is hidden (0: no such check).
  void set_depth_check(const std::vector<double>& depth_unit_mm, double occluder_mm);

  // Camera k's world -> camera pose for the next compute() (a camera the robot carries: where
  // it was at this frame's capture); its intrinsics stay. Until set, its calibrated pose.
  // RT-safe; false on a wrong index.
  bool set_pose(std::size_t k, const cv::Matx33d& R, const cv::Vec3d& t) noexcept;

  // nodes: the grid's world positions (mm). seen[i]: bit k set when camera k (of those in
  // camera_mask) sees node i. depth: per camera its depth image (CV_16UC1, full resolution; empty
  // or missing: no depth check for it). RT-safe; false on a wrong size.
  bool compute(std::span<const Eigen::Vector3d> nodes, std::uint32_t camera_mask,
               std::span<std::uint32_t> seen, std::span<const cv::Mat> depth = {}) noexcept;

  // Node-camera pairs the last compute() hid by the depth check alone (the model's z-buffer
  // showed the node to that camera).
  [[nodiscard]] int occluded_by_depth() const noexcept { return occluded_; }

 private:
  struct View {
    vision::Camera cam;  // intrinsics scaled by 1/scale
    int w = 0, h = 0;
    std::vector<float> zbuf;          // camera z, mm; +inf: no surface
    std::vector<std::int32_t> cell;   // grid cell (j * (nodes_u - 1) + i) of the nearest surface
  };
  std::vector<View> views_;
  std::vector<Eigen::Vector3d> proj_;  // per node: pixel x, y (scaled), camera z (<= 0: behind)
  std::vector<double> unit_mm_;        // per camera: one depth count, mm
  double occluder_mm_ = 0.0;           // 0: no depth check
  int scale_ = 1;
  int nu_ = 0, nv_ = 0, cells_ = 1;
  int occluded_ = 0;

  // Camera z (mm) of the farthest valid depth pixel within kDepthWindow of full-resolution pixel
  // (x, y); 0 when none is valid.
  [[nodiscard]] double farthest_depth_mm(const cv::Mat& depth, double unit_mm, double x,
                                         double y) const noexcept;
};

}  // namespace crease::depth
