// Prediction of key-points between (and briefly through gaps in) observations: the vision
// loop runs at 15 Hz, the model at 60 Hz, and markers drop out, hide behind a hand or turn
// away (a flap folded past 90 deg shows the cameras its back). Each key-point id keeps its
// last two observations; its predicted world position at time t is the last one plus
// (t - t_last) times the velocity between the two, for at most max_extrapolate_s after it was
// last seen (while newer observations leave it out): after that it is no longer predicted, and
// the model's physics holds that part.
// With bound_by_sheet, a key-point that was not in the newest observation is kept within its
// sheet distance (plus slack_mm) of every key-point that was: paper does not stretch, so two
// sheet points are never further apart in the world than on the sheet. Constant velocity
// along a rotating flap runs off along the tangent; the bound brings it back to what the
// sheet allows. Storage is fixed at construction; RT after that.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "sheet_model.h"

namespace crease::sheet {

class KeypointPredictor {
 public:
  // ids: key-point ids are in [0, ids).
  explicit KeypointPredictor(int ids, PredictorParams p = {})
      : slots_(static_cast<std::size_t>(std::max(ids, 0))), p_(p) {}

  // Records an observation; non-finite ones and unknown ids are ignored. RT.
  void observe(int id, Vec2 sheet_mm, Vec3 world_mm, double t_s) noexcept {
    if (id < 0 || id >= static_cast<int>(slots_.size()) || !is_finite(world_mm) || !std::isfinite(t_s))
      return;
    Slot& s = slots_[id];
    if (s.seen && t_s > s.t && t_s - s.t <= p_.max_gap_s) {
      s.vel = (1.0 / (t_s - s.t)) * (world_mm - s.world);
      s.has_vel = true;
    } else if (!s.seen || t_s - s.t > p_.max_gap_s) {
      s.has_vel = false;
    }
    s.seen = true;
    s.t = t_s;
    s.world = world_mm;
    s.sheet = sheet_mm;
    if (!have_newest_ || t_s > newest_t_) newest_t_ = t_s;
    have_newest_ = true;
  }

  // Writes predicted targets at time t into out; returns how many: first those of the newest
  // observation (seen_count() of them), then the ones predicted through a gap. RT.
  int predict(double t_s, std::span<TargetPoint> out) noexcept {
    int n = 0;
    for (int pass = 0; pass < 2; ++pass) {
      for (const Slot& s : slots_) {
        if (!s.seen || n >= static_cast<int>(out.size())) continue;
        const bool fresh = s.t >= newest_t_;  // in the newest observation
        if (fresh != (pass == 0)) continue;
        // Unseen: missing from observations for longer than max_extrapolate_s (counted from the
        // newest, so a slow or late vision frame drops nothing it still shows).
        if (!fresh && newest_t_ - s.t > p_.max_extrapolate_s) continue;
        const double age = std::min(t_s - s.t, p_.max_extrapolate_s);  // extrapolated at most this long
        const Vec3 p = s.has_vel && age > 0 ? s.world + age * s.vel : s.world;
        out[n++] = {p, s.sheet};
      }
      if (pass == 0) n_seen_ = n;
    }
    if (p_.bound_by_sheet) bound(out.first(static_cast<std::size_t>(n)));
    return n;
  }
  // How many of the last predict's targets were in the newest observation (they come first).
  [[nodiscard]] int seen_count() const noexcept { return n_seen_; }

  // The fastest velocity of the key-points last observed within memory_s before t (mm/s). RT.
  [[nodiscard]] double fastest_speed(double t_s, double memory_s) const noexcept {
    double v2 = 0;
    for (const Slot& s : slots_)
      if (s.seen && s.has_vel && t_s - s.t <= memory_s) v2 = std::max(v2, dot(s.vel, s.vel));
    return std::sqrt(v2);
  }

  void clear() noexcept {
    std::fill(slots_.begin(), slots_.end(), Slot{});
    have_newest_ = false;
    newest_t_ = 0;
    n_seen_ = 0;
  }

  [[nodiscard]] const PredictorParams& params() const noexcept { return p_; }

 private:
  // Each unseen key-point, in turn, moved onto the sphere of its sheet distance (+ slack)
  // around each seen one it is further from (one Gauss-Seidel pass; the seen stay put).
  void bound(std::span<TargetPoint> out) noexcept {
    const std::size_t n = out.size(), seen = static_cast<std::size_t>(n_seen_);
    for (std::size_t i = seen; i < n; ++i) {
      Vec3 p = out[i].world_mm;
      for (std::size_t j = 0; j < seen; ++j) {
        const double du = out[i].sheet_mm.u - out[j].sheet_mm.u, dv = out[i].sheet_mm.v - out[j].sheet_mm.v;
        const double allowed = std::sqrt(du * du + dv * dv) + p_.slack_mm;
        const Vec3 d = p - out[j].world_mm;
        const double len = norm(d);
        if (len > allowed) p = out[j].world_mm + (allowed / len) * d;
      }
      out[i].world_mm = p;
    }
  }

  struct Slot {
    Vec3 world, vel;
    Vec2 sheet;
    double t = 0;
    bool seen = false, has_vel = false;
  };
  std::vector<Slot> slots_;
  int n_seen_ = 0;  // of the last predict's outputs, the first n_seen_ are in the newest observation
  PredictorParams p_;
  double newest_t_ = 0;
  bool have_newest_ = false;
};

}  // namespace crease::sheet
