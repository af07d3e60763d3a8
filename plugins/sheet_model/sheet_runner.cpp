#include "sheet_runner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "depth_surface_normals.h"
#include "sheet_state_writer.h"
#include "xpbd_sheet.h"

namespace crease::sheet {

SheetRunner::SheetRunner(const SheetParams& params, double table_height_mm)
    : SheetRunner(std::make_unique<XpbdSheet>(params), table_height_mm) {}

SheetRunner::SheetRunner(std::unique_ptr<SheetModel> model, double table_height_mm)
    : model_(std::move(model)), predictor_(kMarkerIds * 5, model_->params().predictor), coupling_(model_->params().solver.coupling) {
  if (std::isfinite(table_height_mm)) {
    world_.add_table(table_height_mm);
    model_->set_collision_world(&world_);
  }
  predicted_.resize(SheetModel::kMaxTargets);
  keypoint_obs_.resize(SheetModel::kMaxKeypoints);
  external_.resize(TargetPoints::kCapacity);
  depth_.resize(DepthTargets::kCapacity);
  depth_used_targets_.resize(DepthTargets::kCapacity);
  depth_node_.resize(DepthTargets::kCapacity);
  node_depth_.assign(model_->node_count(), -1);
  node_last_.resize(model_->node_count());
  node_vel_.resize(model_->node_count());
  node_last_ns_.assign(model_->node_count(), std::numeric_limits<std::int64_t>::min());
  last_good_.assign(model_->positions().begin(), model_->positions().end());
  normals_.resize(model_->node_count());
  strain_.resize(model_->link_count());
}

void SheetRunner::observe_keypoints(const Keypoints& k) noexcept {
  if (!have_epoch_) {
    epoch_ns_ = k.timestamp_ns;
    have_epoch_ = true;
  }
  const double t = seconds(k.timestamp_ns);
  const std::uint32_t n = std::min(k.count, Keypoints::kCapacity);
  for (std::uint32_t i = 0; i < n; ++i) {
    const Keypoint& p = k.points[i];
    const int id = static_cast<int>(p.marker_id) * 5 + std::min<int>(p.corner, 4);
    predictor_.observe(id, {p.sheet_mm[0], p.sheet_mm[1]}, {p.world_mm[0], p.world_mm[1], p.world_mm[2]}, t);
  }
}

void SheetRunner::set_targets(const TargetPoints& t) noexcept {
  n_external_ = 0;
  const std::uint32_t n = std::min(t.count, TargetPoints::kCapacity);
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto& p = t.points[i];
    external_[n_external_++] = {{p.world_mm[0], p.world_mm[1], p.world_mm[2]}, {p.sheet_mm[0], p.sheet_mm[1]}};
  }
}

void SheetRunner::set_depth_targets(const DepthTargets& t) noexcept {
  n_depth_ = 0;
  depth_stamp_ns_ = t.timestamp_ns;
  const Grid& g = model_->grid();
  const double du = g.du, dv = g.dv;
  const std::uint32_t n = std::min(t.count, DepthTargets::kCapacity);
  for (std::uint32_t k = 0; k < n; ++k) {
    const auto& p = t.points[k];
    const NormalTarget nt{{p.world_mm[0], p.world_mm[1], p.world_mm[2]}, {p.sheet_mm[0], p.sheet_mm[1]}, p.weight};
    // The grid node the target is on, if it is on one (the depth tracker's are).
    const double fi = nt.sheet_mm.u / du, fj = nt.sheet_mm.v / dv;
    const long i = std::lround(fi), j = std::lround(fj);
    std::int32_t node = -1;
    if (std::isfinite(fi) && std::isfinite(fj) && std::abs(fi - double(i)) < 1e-3 && std::abs(fj - double(j)) < 1e-3 &&
        i >= 0 && j >= 0 && i < g.w && j < g.h && is_finite(nt.world_mm)) {
      node = static_cast<std::int32_t>(j * g.w + i);
      const std::int64_t last = node_last_ns_[node];
      const bool near = last != std::numeric_limits<std::int64_t>::min() && t.timestamp_ns > last &&
                        static_cast<double>(t.timestamp_ns - last) * 1e-9 <= kDepthMaxGapS;
      node_vel_[node] = near ? (1e9 / static_cast<double>(t.timestamp_ns - last)) * (nt.world_mm - node_last_[node]) : Vec3{};
      node_last_[node] = nt.world_mm;
      node_last_ns_[node] = t.timestamp_ns;
    }
    depth_node_[n_depth_] = node;
    depth_[n_depth_++] = nt;
  }
  // The observed surface's normal at each target on a grid node (depth_surface_normals.h).
  estimate_surface_normals_rt(
      g.w, g.h, std::span<NormalTarget>(depth_.data(), static_cast<std::size_t>(n_depth_)),
      std::span<const std::int32_t>(depth_node_.data(), static_cast<std::size_t>(n_depth_)),
      node_depth_);
}

void SheetRunner::apply(const SheetCreaseEvent& e) noexcept {
  switch (e.op) {
    case SheetCreaseEvent::Op::add:  // the model's id shows as the crease's slot
      (void)model_->add_crease({{e.a_mm[0], e.a_mm[1]}, {e.b_mm[0], e.b_mm[1]}});
      break;
    case SheetCreaseEvent::Op::remove:
      model_->remove_crease(e.id);
      break;
    case SheetCreaseEvent::Op::clear:
      for (int c = 0; c < CreaseSet::kCapacity; ++c) model_->remove_crease(c);
      break;
  }
}

void SheetRunner::apply(const SheetMemorizeEvent& e) noexcept {
  if (!model_->state_finite()) return;
  if (e.whole_sheet) {
    model_->memorize_all();
  } else {
    model_->memorize_region({{e.min_mm[0], e.min_mm[1]}, {e.max_mm[0], e.max_mm[1]}});
  }
}

void SheetRunner::apply(const SheetResetEvent&) noexcept {
  model_->reset_rt();
  last_fit_mm_ = std::numeric_limits<double>::infinity();
  fit_good_s_ = 0;
  predictor_.clear();
  n_external_ = 0;
  n_depth_ = 0;
  std::fill(node_last_ns_.begin(), node_last_ns_.end(), std::numeric_limits<std::int64_t>::min());
  last_good_.assign(model_->positions().begin(), model_->positions().end());
}

bool SheetRunner::step_rt(double dt_s, std::int64_t now_ns, SheetState& out) noexcept {
  if (!have_epoch_) {
    epoch_ns_ = now_ns;
    have_epoch_ = true;
  }
  const int n_obs = predictor_.predict(seconds(now_ns), predicted_);
  observations_ = static_cast<std::uint32_t>(n_obs);
  int n = n_obs;
  for (int i = 0; i < n_external_ && n < static_cast<int>(predicted_.size()); ++i) predicted_[n++] = external_[i];
  const std::span<const TargetPoint> all(predicted_.data(), static_cast<std::size_t>(n));
  if (coupling_ == Coupling::keypoints) {
    const int k = std::min(n_obs, static_cast<int>(keypoint_obs_.size()));
    for (int i = 0; i < k; ++i) keypoint_obs_[i] = {predicted_[i].world_mm, predicted_[i].sheet_mm};
    model_->set_keypoints(std::span<const KeypointObs>(keypoint_obs_.data(), static_cast<std::size_t>(k)));
    model_->set_targets(all.subspan(static_cast<std::size_t>(n_obs)));
  } else {
    model_->set_targets(all);
  }
  const double memory = model_->params().predictor.unseen_speed_memory_s;
  const SolverParams& sp = model_->params().solver;
  fit_good_s_ = last_fit_mm_ <= sp.learn_fit_mm ? fit_good_s_ + dt_s : 0.0;
  const bool fits = fit_good_s_ >= sp.learn_after_s;
  model_->set_unseen_speed_limit(0.0);  // none while the model catches up with what it sees
  if (memory > 0 && fits) {
    // At least 1 mm/s (a limit of 0 would be none). The key-points predicted through a gap
    // [seen_count, n_obs) are not seen; the external targets are commands, as good as seen.
    const InputRange predicted{predictor_.seen_count(), n_obs};
    const bool springs = coupling_ != Coupling::keypoints;
    model_->set_unseen_speed_limit(std::max(predictor_.fastest_speed(seconds(now_ns), memory), 1.0),
                                   springs ? predicted : InputRange{},
                                   springs ? InputRange{} : predicted);
  }
  model_->set_links_learn(observations_ == 0 || fits);
  const bool depth_fresh = n_depth_ > 0 && static_cast<double>(now_ns - depth_stamp_ns_) * 1e-9 <= kDepthMaxAgeS;
  int nd = 0;
  if (depth_fresh) {
    const double ahead = std::clamp(static_cast<double>(now_ns - depth_stamp_ns_) * 1e-9, 0.0, kDepthMaxPredictS);
    for (int k = 0; k < n_depth_; ++k) {
      NormalTarget nt = depth_[k];
      if (depth_predict_ && depth_node_[k] >= 0) nt.world_mm += ahead * node_vel_[depth_node_[k]];
      depth_used_targets_[nd++] = nt;
    }
  }
  depth_used_ = model_->set_normal_targets(
      std::span<const NormalTarget>(depth_used_targets_.data(), static_cast<std::size_t>(nd)));
  model_->save_links_rt();  // with last_good_: the state this step starts from
  model_->step_rt(dt_s);
  ++steps_;
  bool ok = model_->state_finite();
  if (ok) {
    for (std::size_t i = 0; i < last_good_.size(); ++i) last_good_[i] = model_->positions()[i];
  } else {
    model_->restore_links_rt();
    model_->set_positions(last_good_);
    ++rollbacks_;
  }
  fill_state(now_ns, out);
  return ok;
}

void SheetRunner::fill_state(std::int64_t now_ns, SheetState& out) noexcept {
  write_sheet_state(*model_, normals_, strain_, now_ns, steps_, out);
  // Fit: mean distance of the used targets to the model's sheet points.
  double err = 0;
  int used = 0;
  const int nt = static_cast<int>(observations_);
  for (int t = 0; t < nt; ++t) {
    err += norm(model_->interpolate(predicted_[t].sheet_mm) - predicted_[t].world_mm);
    ++used;
  }
  out.fit_error_mm = used > 0 ? static_cast<float>(err / used) : -1.0f;
  last_fit_mm_ = used > 0 ? err / used : std::numeric_limits<double>::infinity();
  out.observations = observations_;
  out.rollbacks = rollbacks_;
}

}  // namespace crease::sheet
