// Constant-velocity prediction of key-points between (and through gaps in) observations:
// the vision loop runs at 15 Hz, the model at 60 Hz, and markers drop out or hide behind a
// hand. Each key-point id keeps its last two observations; its predicted world position at
// time t is the last one plus (t - t_last) times the velocity between the two, for at most
// max_extrapolate_s after it was last seen. Storage is fixed at construction; RT after that.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "sheet_model.h"

namespace crease::sheet {

class KeypointPredictor {
 public:
  // ids: key-point ids are in [0, ids). max_gap_s: two observations further apart than this
  // give no velocity. max_extrapolate_s: how long an unseen key-point is still predicted.
  KeypointPredictor(int ids, double max_gap_s = 0.25, double max_extrapolate_s = 1.5)
      : slots_(static_cast<std::size_t>(std::max(ids, 0))), max_gap_s_(max_gap_s),
        max_extrapolate_s_(max_extrapolate_s) {}

  // Records an observation; non-finite ones and unknown ids are ignored. RT.
  void observe(int id, Vec2 sheet_mm, Vec3 world_mm, double t_s) noexcept {
    if (id < 0 || id >= static_cast<int>(slots_.size()) || !is_finite(world_mm) || !std::isfinite(t_s))
      return;
    Slot& s = slots_[id];
    if (s.seen && t_s > s.t && t_s - s.t <= max_gap_s_) {
      s.vel = (1.0 / (t_s - s.t)) * (world_mm - s.world);
      s.has_vel = true;
    } else if (!s.seen || t_s - s.t > max_gap_s_) {
      s.has_vel = false;
    }
    s.seen = true;
    s.t = t_s;
    s.world = world_mm;
    s.sheet = sheet_mm;
  }

  // Writes predicted targets at time t into out; returns how many. RT.
  int predict(double t_s, std::span<TargetPoint> out) const noexcept {
    int n = 0;
    for (const Slot& s : slots_) {
      if (!s.seen || n >= static_cast<int>(out.size())) continue;
      const double age = t_s - s.t;
      if (age > max_extrapolate_s_) continue;
      const Vec3 p = s.has_vel && age > 0 ? s.world + age * s.vel : s.world;
      out[n++] = {p, s.sheet};
    }
    return n;
  }

  void clear() noexcept { std::fill(slots_.begin(), slots_.end(), Slot{}); }

 private:
  struct Slot {
    Vec3 world, vel;
    Vec2 sheet;
    double t = 0;
    bool seen = false, has_vel = false;
  };
  std::vector<Slot> slots_;
  double max_gap_s_, max_extrapolate_s_;
};

}  // namespace crease::sheet
