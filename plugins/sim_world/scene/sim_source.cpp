#include "plugins/sim_world/scene/sim_source.h"

#include <random>

namespace crease::vision {

std::vector<CameraDropout> draw_dropouts(std::uint64_t seed, int count, std::uint64_t frames,
                                         std::uint64_t from_frame, std::uint64_t to_frame, int cameras) {
  std::vector<CameraDropout> out;
  if (count <= 0 || cameras <= 0 || frames == 0) return out;
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0xD1);
  std::uniform_int_distribution<int> cam(0, cameras - 1);
  std::uniform_int_distribution<std::uint64_t> first(from_frame, std::max(from_frame, to_frame));
  for (int k = 0; k < count; ++k) {
    CameraDropout d;
    d.camera = cam(rng);
    d.first_frame = first(rng);
    d.frames = frames;
    out.push_back(d);
  }
  return out;
}

SimSource::SimSource(std::shared_ptr<const ViewRenderer> renderer,
                     std::function<SheetMesh(std::uint64_t)> mesh_at, RenderOptions options,
                     std::int64_t period_ns, std::int64_t start_ns, std::vector<CameraDropout> dropouts)
    : renderer_(std::move(renderer)),
      mesh_at_(std::move(mesh_at)),
      options_(options),
      period_ns_(period_ns),
      start_ns_(start_ns),
      dropouts_(std::move(dropouts)) {}

bool SimSource::grab(Frame& frame) {
  const SheetMesh mesh = mesh_at_(next_);
  if (shapes_now_) shapes_now_(shapes_);
  RenderOptions o = options_;
  o.seed = options_.seed + next_;
  frame.index = next_;
  // The scene's own time when it has one (a truth from the simulated world), else the nominal one.
  frame.timestamp_ns = mesh.timestamp_ns >= 0
                           ? mesh.timestamp_ns
                           : start_ns_ + static_cast<std::int64_t>(next_) * period_ns_;
  frame.images.resize(renderer_->cameras().size());
  for (std::size_t k = 0; k < frame.images.size(); ++k) {
    bool dropped = false;
    for (const CameraDropout& d : dropouts_)
      dropped = dropped || (d.camera == static_cast<int>(k) && next_ >= d.first_frame && next_ < d.first_frame + d.frames);
    if (dropped) {
      frame.images[k] = cv::Mat();  // delivers nothing this frame
      continue;
    }
    RenderedView v;  // fresh buffers (frame.images[k] keeps this one), or the caller's
    if (frame.fill_in_place) v.image = frame.images[k];
    renderer_->render(static_cast<int>(k), mesh, o, v, shapes_);
    frame.images[k] = v.image;
  }
  ++next_;
  return true;
}

}  // namespace crease::vision
