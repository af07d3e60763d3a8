#include "plugins/fold_sequence/fold_spec.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/params.h"
#include "core/port_types/keypoints.h"
#include "plugins/fold_sequence/states.h"

namespace crease::fold {
namespace {

constexpr std::string_view kTools[] = {"ff_pad",  "mf_pad",  "rf_pad",  "lf_pad",  "th_pad",     "ff_back",
                                       "mf_back", "rf_back", "lf_back", "th_back", "palm_front", "flange"};
constexpr std::string_view kFingers[] = {"ff", "mf", "rf", "lf", "th"};

// A list of exactly n numbers at `key`; when absent, an error if required, else out is left as it is.
void numbers(const Params& p, const char* key, int n, double* out, bool required = true) {
  const YAML::Node node = p.raw(key);
  if (!node) {
    if (required) p.fail(key, "required");
    return;
  }
  if (!node.IsSequence() || node.size() != static_cast<std::size_t>(n))
    p.fail(key, "expected a list of " + std::to_string(n) + " numbers");
  for (int i = 0; i < n; ++i) {
    const YAML::Node e = node[static_cast<std::size_t>(i)];
    double v = 0;
    if (!e.IsScalar()) p.fail(key, "element " + std::to_string(i) + " is not a number");
    try {
      v = e.as<double>();
    } catch (const YAML::Exception&) {
      p.fail(key, "element " + std::to_string(i) + " is not a number: '" + e.Scalar() + "'");
    }
    if (!std::isfinite(v)) p.fail(key, "element " + std::to_string(i) + " is not finite");
    out[i] = v;
  }
}

void floats(const Params& p, const char* key, int n, float* out) {
  std::vector<double> v(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = out[i];
  numbers(p, key, n, v.data(), false);
  for (int i = 0; i < n; ++i) out[i] = static_cast<float>(v[static_cast<std::size_t>(i)]);
}

void quaternion(const Params& p, const char* key, double* q, bool required = false) {
  numbers(p, key, 4, q, required);
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(n - 1.0) > 1e-3) p.fail(key, "must be a unit quaternion [x, y, z, w], its norm is " + format_number(n));
}

// A sheet point given as [u, v, h] (h above the sheet): stored as the sheet frame's (u, v, -h).
void sheet_point(const Params& p, const char* key, double* out) {
  numbers(p, key, 3, out);
  out[2] = -out[2];
}

// The grasp's list KEY of at most kMaxGraspPath `{at_mm}` points on the way to BEFORE, each
// with its (required) `orientation` when ORIENTATION is given, and its `frame` (sheet, the
// default, or world: at_mm is then x, y, z up) when WORLD is; returns how many.
int grasp_points(const Params& p, const char* key, const char* before, double (*mm)[3],
                 double (*orientation)[4], bool* world = nullptr) {
  const std::vector<Params> list = p.list(key);
  if (list.size() > static_cast<std::size_t>(kMaxGraspPath))
    p.fail(key, "expected at most " + std::to_string(kMaxGraspPath) + " points before " + before);
  const int n = static_cast<int>(list.size());
  for (int i = 0; i < n; ++i) {
    const Params& v = list[static_cast<std::size_t>(i)];
    sheet_point(v, "at_mm", mm[i]);
    if (orientation != nullptr) quaternion(v, "orientation", orientation[i], true);
    if (world == nullptr) continue;
    const std::string frame = v.get<std::string>("frame", "sheet");
    if (frame != "sheet" && frame != "world")
      v.fail("frame", "expected sheet or world, got '" + frame + "'");
    world[i] = frame == "world";
    if (world[i]) mm[i][2] = -mm[i][2];  // z up as given
  }
  return n;
}

std::uint8_t tool(const Params& p, const char* key, std::uint8_t fallback) {
  if (!p.has(key)) return fallback;
  const std::string name = p.get<std::string>(key);
  const int t = tool_index(name);
  if (t < 0) p.fail(key, "unknown tool frame '" + name + "' (ff_pad .. th_pad, ff_back .. th_back, palm_front, flange)");
  return static_cast<std::uint8_t>(t);
}

std::uint8_t fingers(const Params& p, const char* key, std::uint8_t fallback) {
  const YAML::Node node = p.raw(key);
  if (!node) return fallback;
  if (!node.IsSequence() || node.size() == 0) p.fail(key, "expected a non-empty list of fingers (ff mf rf lf th)");
  std::uint8_t mask = 0;
  for (const auto& e : node) {
    const std::string name = e.IsScalar() ? e.Scalar() : std::string("?");
    const int f = finger_index(name);
    if (f < 0) p.fail(key, "unknown finger '" + name + "' (ff mf rf lf th)");
    mask = static_cast<std::uint8_t>(mask | (1u << f));
  }
  return mask;
}

MotionLimits limits(const Params& p, const char* key, const MotionLimits& d) {
  const Params c = p.child(key);
  MotionLimits m;
  m.speed_mm_s = c.get_in_range<float>("speed_mm_s", d.speed_mm_s, 0.1f, 1000.0f);
  m.accel_mm_s2 = c.get_in_range<float>("accel_mm_s2", d.accel_mm_s2, 1.0f, 20000.0f);
  m.angular_speed_rad_s = c.get_in_range<float>("angular_speed_rad_s", d.angular_speed_rad_s, 0.01f, 10.0f);
  m.angular_accel_rad_s2 = c.get_in_range<float>("angular_accel_rad_s2", d.angular_accel_rad_s2, 0.01f, 100.0f);
  m.stop_accel_mm_s2 = c.get_in_range<float>("stop_accel_mm_s2", d.stop_accel_mm_s2, 1.0f, 50000.0f);
  if (m.stop_accel_mm_s2 < m.accel_mm_s2) c.fail("stop_accel_mm_s2", "must be at least accel_mm_s2 (arm_motion's rule)");
  return m;
}

// The parts of a ContactStep; `at` read unless the step places itself (harden).
ContactStep contact_step(const Params& c, std::uint8_t tool_fallback, bool with_at) {
  ContactStep s;
  s.tool = tool(c, "tool", tool_fallback);
  s.fingers = fingers(c, "fingers", 0x01);
  if (with_at) numbers(c, "at_mm", 2, s.at_mm);
  s.approach_height_mm = c.get_in_range<double>("approach_height_mm", 30.0, 0.0, 300.0);
  s.contact_depth_mm = c.get_in_range<double>("contact_depth_mm", 5.0, 0.0, 50.0);
  s.force_n = c.get_in_range<double>("force_n", 1.0, 0.0, 10.0);
  quaternion(c, "orientation", s.orientation);
  return s;
}

void read(const Params& p, FoldSpec& f) {
  f.name = p.get<std::string>("name");
  if (f.name.empty() || f.name.size() >= 16) p.fail("name", "must be 1 to 15 characters");
  {
    const YAML::Node line = p.raw("fold_line_mm");
    const char* shape = "expected [[u0, v0], [u1, v1]] (sheet mm)";
    if (!line || !line.IsSequence() || line.size() != 2) p.fail("fold_line_mm", shape);
    for (std::size_t e = 0; e < 2; ++e) {
      const YAML::Node pt = line[e];
      if (!pt.IsSequence() || pt.size() != 2) p.fail("fold_line_mm", shape);
      for (std::size_t k = 0; k < 2; ++k) {
        if (!pt[k].IsScalar()) p.fail("fold_line_mm", shape);
        try {
          f.fold_line_mm[e][k] = pt[k].as<double>();
        } catch (const YAML::Exception&) {
          p.fail("fold_line_mm", std::string(shape) + ": '" + pt[k].Scalar() + "' is not a number");
        }
        if (!std::isfinite(f.fold_line_mm[e][k])) p.fail("fold_line_mm", "not finite");
      }
    }
    if (std::hypot(f.fold_line_mm[1][0] - f.fold_line_mm[0][0], f.fold_line_mm[1][1] - f.fold_line_mm[0][1]) < 1.0)
      p.fail("fold_line_mm", "its end points are less than 1 mm apart");
  }

  const double t = p.get_in_range<double>("timeout_s", 20.0, 0.1, 3600.0);
  f.timeout_s.fill(t);
  f.timeout_s[static_cast<std::size_t>(S::idle)] = 0;  // 0: none (waiting for the operator)
  f.timeout_s[static_cast<std::size_t>(S::done)] = 0;
  f.timeout_s[static_cast<std::size_t>(S::aborted)] = 0;
  // The steps (a)-(h), superstates of several motions each: step_timeout_s unless given.
  const double step_t = p.get_in_range<double>("step_timeout_s", 120.0, 0.1, 3600.0);
  for (S s : {S::shift, S::grasp, S::bend, S::fixate_layer, S::refixate, S::swipe, S::harden, S::finish})
    f.timeout_s[static_cast<std::size_t>(s)] = step_t;
  f.timeout_s[static_cast<std::size_t>(S::fold)] = 600;
  f.timeout_s[static_cast<std::size_t>(S::abort)] = 60;
  if (const YAML::Node ts = p.raw("timeouts_s")) {
    if (!ts.IsMap()) p.fail("timeouts_s", "expected a map of state paths to seconds");
    const Params tp = p.child("timeouts_s");
    for (const auto& kv : ts) {
      const std::string path = kv.first.as<std::string>();
      const S s = state_by_path(path);
      if (s == S::count || s == S::idle || s == S::done || s == S::aborted)
        tp.fail(path, "not a state with a timeout (e.g. fold, fold/bend/follow_via, abort/lift)");
      f.timeout_s[static_cast<std::size_t>(s)] = tp.get_in_range<double>(path, t, 0.1, 3600.0);
    }
  }

  const Params sn = p.child("sensing");
  f.vision_lost_max_s = sn.get_in_range<double>("vision_lost_max_s", 0.5, 0.01, 60.0);
  f.pinch_lost_mm = sn.get_in_range<double>("pinch_lost_mm", 0.0, 0.0, 1000.0);
  f.pinch_lost_s = sn.get_in_range<double>("pinch_lost_s", 0.0, 0.0, 60.0);
  f.fold_lost_mm = sn.get_in_range<double>("fold_lost_mm", 0.0, 0.0, 1000.0);
  f.flap_seen_points =
      sn.get_in_range<std::uint32_t>("flap_seen_points", 0u, 0u, Keypoints::kCapacity);
  f.flap_seen_s = sn.get_in_range<double>("flap_seen_s", 0.3, 0.0, 60.0);
  f.min_observations = sn.get_in_range<std::uint32_t>("min_observations", 1u, 0u, 100000u);
  f.sheet_max_age_s = sn.get_in_range<double>("sheet_max_age_s", 0.2, 0.001, 10.0);
  f.status_max_age_s = sn.get_in_range<double>("status_max_age_s", 0.05, 0.001, 10.0);

  const Params m = p.child("motion");
  f.approach = limits(m, "approach", MotionLimits{});
  f.contact = limits(m, "contact", MotionLimits{20, 200, 0.5f, 3, 2000});
  f.slide = limits(m, "slide", MotionLimits{30, 200, 0.5f, 3, 2000});
  f.fold = limits(m, "fold", MotionLimits{});
  f.retreat = limits(m, "retreat", MotionLimits{});

  const Params h = p.child("hands");
  const std::string pinching = h.get<std::string>("pinching", "left");
  if (pinching != "left" && pinching != "right") h.fail("pinching", "must be left or right, not '" + pinching + "'");
  f.pinching_side = pinching == "right" ? 0 : 1;
  floats(h, "open_rad", kHandJoints, f.open_rad);
  std::copy(std::begin(f.open_rad), std::end(f.open_rad), std::begin(f.prepinch_rad));
  floats(h, "prepinch_rad", kHandJoints, f.prepinch_rad);
  floats(h, "pinch_rad", kHandJoints, f.pinch_rad);
  if (h.has("release_stiffness")) {
    floats(h, "release_stiffness", kHandJoints, f.release_stiffness);
    for (int j = 0; j < kHandJoints; ++j)
      if (f.release_stiffness[j] < 0.0f || f.release_stiffness[j] > 655.35f)
        h.fail("release_stiffness", "element " + std::to_string(j) + " must be within [0, 655.35] N m/rad");
    f.has_release_stiffness = true;
  }
  f.posture_ramp_s = h.get_in_range<double>("ramp_s", 0.3, 0.0, 60.0);
  f.release_ramp_s = h.get_in_range<double>("release_ramp_s", f.posture_ramp_s, 0.0, 60.0);
  f.force_ramp_s = h.get_in_range<double>("force_ramp_s", 0.1, 0.0, 60.0);

  const Params a = p.child("shift");
  f.shift = contact_step(a, 0, true);
  numbers(a, "corner_mm", 2, f.corner_mm);
  numbers(a, "corner_target_mm", 2, f.corner_target_mm);
  f.shift_tolerance_mm = a.get_in_range<double>("tolerance_mm", 3.0, 0.0, 100.0);
  f.max_slide_mm = a.get_in_range<double>("max_slide_mm", 150.0, 0.0, 1000.0);
  f.max_slides = a.get_in_range<int>("max_slides", 4, 1, 20);
  f.shift_settle_s = a.get_in_range<double>("settle_s", 0.3, 0.0, 10.0);
  f.slide_height_mm = a.get_in_range<double>("slide_height_mm", 0.0, -20.0, 50.0);
  const std::string shifter = a.get<std::string>("hand", "fixing");
  if (shifter != "fixing" && shifter != "pinching")
    a.fail("hand", "must be fixing or pinching, not '" + shifter + "'");
  f.shift_role = shifter == "pinching" ? 1 : 0;  // machine.h's role indices: kFixing 0, kPinching 1
  f.shift_lift_mm = a.get_in_range<double>("lift_mm", 100.0, 0.0, 500.0);

  const Params b = p.child("grasp");
  f.fixate_force_n = b.get_in_range<double>("fixate_force_n", 2.0, 0.0, 10.0);
  f.grasp_tool = tool(b, "tool", 4);
  f.pinch_fingers = fingers(b, "pinch_fingers", 0x11);
  f.pinch_force_n = b.get_in_range<double>("pinch_force_n", 0.2, 0.01, 10.0);
  f.grasp_above_via_count = grasp_points(b, "above_via", "above_mm", f.grasp_above_via_mm,
                                         f.grasp_above_via_orientation, f.grasp_above_via_world);
  sheet_point(b, "above_mm", f.grasp_above_mm);
  f.grasp_path_count = grasp_points(b, "path", "at_mm", f.grasp_path_mm, nullptr);
  sheet_point(b, "at_mm", f.grasp_at_mm);
  quaternion(b, "orientation", f.grasp_orientation);
  if (f.shift_role == 1) {
    if (!b.has("fixate"))
      b.fail("fixate", "required when shift.hand is pinching: where the fixing hand fixates");
    f.fixate = contact_step(b.child("fixate"), 0, true);
  } else {
    f.fixate = f.shift;  // the fixing hand stays where it shifted
  }

  const Params c = p.child("bend");
  const std::vector<Params> via = c.list("via");
  if (via.empty() || via.size() > static_cast<std::size_t>(kMaxVia))
    c.fail("via", "expected 1 to " + std::to_string(kMaxVia) + " via points");
  f.via_count = static_cast<int>(via.size());
  for (int i = 0; i < f.via_count; ++i) {
    const Params& v = via[static_cast<std::size_t>(i)];
    sheet_point(v, "at_mm", f.via_mm[i]);
    f.via_orientation[i][3] = 1;
    quaternion(v, "orientation", f.via_orientation[i]);
  }
  if (c.has("yaw_range_deg") || c.has("yaw_reference_deg")) {
    f.bend_yaw_limited = true;
    if (!c.has("yaw_reference_deg"))
      c.fail("yaw_reference_deg",
             "required with yaw_range_deg: the heading the via points were drawn for");
    f.bend_yaw_reference_deg = c.get_in_range<double>("yaw_reference_deg", 0.0, -180.0, 180.0);
    numbers(c, "yaw_range_deg", 2, f.bend_yaw_range_deg);
    if (!(f.bend_yaw_range_deg[0] <= 0 && f.bend_yaw_range_deg[1] >= 0 &&
          f.bend_yaw_range_deg[0] >= -90 && f.bend_yaw_range_deg[1] <= 90))
      c.fail("yaw_range_deg", "expected [low, high] deg with -90 <= low <= 0 <= high <= 90");
  }

  sheet_point(p.child("fixate_layer"), "lay_mm", f.lay_mm);
  const Params rf = p.child("refixate");
  f.refixate = contact_step(rf, 0, true);
  numbers(rf, "out_mm", 2, f.refixate_out_mm);
  f.refixate_out_force_n = rf.get_in_range<double>("out_force_n", 0.5, 0.0, 10.0);
  f.release_lift_mm = p.get_in_range<double>("release_lift_mm", 30.0, 0.0, 300.0);
  f.park_lift_mm = p.get_in_range<double>("park_lift_mm", 150.0, 0.0, 500.0);
  const Params sw = p.child("swipe");
  f.swipe = contact_step(sw, 0, true);
  sheet_point(sw, "withdraw_mm", f.swipe_withdraw_mm);
  numbers(sw, "to_mm", 2, f.swipe_to_mm);
  const Params hd = p.child("harden");
  f.harden = contact_step(hd, 0, false);
  f.harden_inset_mm = hd.get_in_range<double>("inset_mm", 10.0, 0.0, 200.0);
  f.harden_offset_mm = hd.get_in_range<double>("offset_mm", 0.0, -100.0, 100.0);

  const Params pk = p.child("park");
  const char* sides[2] = {"right", "left"};
  for (int s = 0; s < 2; ++s) {
    const Params ps = pk.child(sides[s]);
    numbers(ps, "at_mm", 3, f.park_mm[s]);
    quaternion(ps, "orientation", f.park_orientation[s]);
  }
}

}  // namespace

int tool_index(const std::string& name) {
  for (std::size_t i = 0; i < std::size(kTools); ++i)
    if (kTools[i] == name) return static_cast<int>(i);
  return -1;
}

int finger_index(const std::string& name) {
  for (std::size_t i = 0; i < std::size(kFingers); ++i)
    if (kFingers[i] == name) return static_cast<int>(i);
  return -1;
}

FoldSpec load_fold_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(SourceLoc{path, 0, 0}, "fold", "cannot read the sequence file");
  std::stringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::ParserException& e) {
    throw ConfigError(SourceLoc{path, e.mark.line + 1, e.mark.column + 1}, "fold", e.msg);
  }
  if (!root.IsMap()) throw ConfigError(SourceLoc{path, 1, 1}, "fold", "expected a map (a sequence file)");
  const Params p(root, path, "fold");
  FoldSpec f;
  f.file = path;
  read(p, f);
  const std::vector<std::string> unused = p.unused_keys();
  if (!unused.empty()) throw ConfigError(unused.front() + ": unknown key");
  return f;
}

}  // namespace crease::fold
