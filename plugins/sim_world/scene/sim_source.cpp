#include "plugins/sim_world/scene/sim_source.h"

namespace crease::vision {

SimSource::SimSource(std::shared_ptr<const ViewRenderer> renderer,
                     std::function<SheetMesh(std::uint64_t)> mesh_at, RenderOptions options,
                     std::int64_t period_ns, std::int64_t start_ns)
    : renderer_(std::move(renderer)),
      mesh_at_(std::move(mesh_at)),
      options_(options),
      period_ns_(period_ns),
      start_ns_(start_ns) {}

bool SimSource::grab(Frame& frame) {
  const SheetMesh mesh = mesh_at_(next_);
  RenderOptions o = options_;
  o.seed = options_.seed + next_;
  frame.index = next_;
  // The scene's own time when it has one (a truth from the simulated world), else the nominal one.
  frame.timestamp_ns = mesh.timestamp_ns >= 0
                           ? mesh.timestamp_ns
                           : start_ns_ + static_cast<std::int64_t>(next_) * period_ns_;
  frame.images.resize(renderer_->cameras().size());
  for (std::size_t k = 0; k < frame.images.size(); ++k) {
    RenderedView v;  // fresh buffers (frame.images[k] keeps this one), or the caller's
    if (frame.fill_in_place) v.image = frame.images[k];
    renderer_->render(static_cast<int>(k), mesh, o, v);
    frame.images[k] = v.image;
  }
  ++next_;
  return true;
}

}  // namespace crease::vision
