// What the simulated cameras (camera_sim, camera_depth_sim) share: the world's sheet handed from
// the RT update to the render thread, and the image options read from the parameters.
// SimTruthFeed: bind() at configure takes the `sheet_truth` input; forward_rt() in update (RT:
// a copy into a latest channel, no allocation) hands the newest truth over; mesh_source() is the
// renderer's `mesh_at` (worker thread: the newest truth handed over, no sheet until there is one).
// SimShapesFeed: the same for the world's arms and hands (`world_shapes`), when the plugin's
// `world_shapes: true` binds it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/params.h"
#include "core/plugin.h"
#include "core/port_types/sheet_state.h"
#include "core/port_types/world_shapes.h"
#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"
#include "rt/latest.h"

namespace crease::vision {

class SimTruthFeed {
 public:
  void bind(crease::PortBinder& ports) { in_ = ports.latest_input<crease::SheetState>("sheet_truth"); }
  void forward_rt(std::int64_t now_ns) noexcept {
    if (in_.poll().is_new()) ch_->write(&in_.value(), now_ns);
  }
  [[nodiscard]] std::function<SheetMesh(std::uint64_t)> mesh_source() const {
    return [ch = ch_, buf = std::make_shared<crease::SheetState>()](std::uint64_t) {
      if (!ch->read(buf.get(), 0).has_data()) return SheetMesh{};
      return mesh_of(*buf);
    };
  }

 private:
  crease::LatestInput<crease::SheetState> in_;
  std::shared_ptr<crease::rt::LatestChannel> ch_ =
      std::make_shared<crease::rt::LatestChannel>(sizeof(crease::SheetState));
};

class SimShapesFeed {
 public:
  // Binds the `world_shapes` input when the parameter `world_shapes` is true (default false).
  void bind(const crease::Params& p, crease::PortBinder& ports) {
    if (!p.get<bool>("world_shapes", false)) return;
    in_ = ports.latest_input<crease::WorldShapes>("world_shapes");
    bound_ = true;
  }
  void forward_rt(std::int64_t now_ns) noexcept {
    if (bound_ && in_.poll().is_new()) ch_->write(&in_.value(), now_ns);
  }
  // The sources' `shapes_now` (worker thread): the newest shapes handed over, none until then;
  // empty when not bound.
  [[nodiscard]] std::function<void(std::vector<SceneShape>&)> shapes_source() const {
    if (!bound_) return {};
    return [ch = ch_, buf = std::make_shared<crease::WorldShapes>()](std::vector<SceneShape>& out) {
      if (!ch->read(buf.get(), 0).has_data()) {
        out.clear();
        return;
      }
      shapes_of(*buf, out);
    };
  }

 private:
  bool bound_ = false;
  crease::LatestInput<crease::WorldShapes> in_;
  std::shared_ptr<crease::rt::LatestChannel> ch_ =
      std::make_shared<crease::rt::LatestChannel>(sizeof(crease::WorldShapes));
};

// seed, noise, blur_px, occluders (the simulated cameras' image parameters).
inline RenderOptions read_render_options(const crease::Params& p) {
  RenderOptions ro;
  ro.seed = static_cast<std::uint64_t>(p.get_in_range<int>("seed", 1, 0, 1 << 30));
  ro.noise_sigma = p.get_in_range<double>("noise", 2.0, 0.0, 50.0);
  ro.blur_sigma_px = p.get_in_range<double>("blur_px", 0.6, 0.0, 5.0);
  ro.occluders = p.get_in_range<int>("occluders", 0, 0, 10);
  return ro;
}

}  // namespace crease::vision
