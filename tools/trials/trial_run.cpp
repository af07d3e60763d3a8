#include "tools/trials/trial_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <set>
#include <stdexcept>
#include <thread>

#include "core/config/daemon_config.h"
#include "core/daemon/daemon.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/sequence_status.h"
#include "core/port_types/sheet_state.h"
#include "core/port_types/world_state.h"
#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/sheet_geometry.h"
#include "plugins/fold_sequence/states.h"
#include "plugins/robot_model/robot_params.h"
#include "plugins/sim_world/bus_fault_plan.h"
#include "plugins/sim_world/randomise.h"
#include "plugins/sim_world/world_config.h"
#include "rt/clock.h"
#include "rt/latest.h"

namespace fs = std::filesystem;

namespace crease::trials {
namespace {

constexpr double kClearMm = 20.0;        // hands clear: every fingertip at least this high
constexpr double kUnderTableMm = 1.0;    // an arm deeper under the table's top: no success
constexpr double kTouchN = 0.05;         // a fingertip pressing more than this touches
constexpr double kAbortWaitS = 90.0;     // the retreat of an operator abort ends within this

template <class T>
std::unique_ptr<rt::LatestReader<T>> reader(PluginHost& host, const std::string& port) {
  const rt::LatestChannel* ch = host.ports().find_latest(port);
  if (ch == nullptr) throw std::runtime_error("the configuration has no port '" + port + "'");
  return std::make_unique<rt::LatestReader<T>>(ch);
}

// The world's draws and its bus faults' plan as the sim_world instance makes them (its
// parameters read by the plugin's own reader, the trial's seed already in them).
std::string describe_draws(const config::DaemonConfig& cfg) {
  for (const auto& p : cfg.plugins) {
    if (p.library != "sim_world") continue;
    const world::WorldPluginConfig w = world::read_world_config(Params(p.params, cfg.file, p.name + ".params"));
    std::string out = world::describe(w.world.seed, world::draw_world(w.world, robot::load_robot_params(w.robot_yaml)));
    if (w.faults) out += "; " + world::describe(world::draw_bus_faults(w.bus_faults));
    return out;
  }
  return "no sim_world instance";
}

std::string world_instance(const config::DaemonConfig& cfg) {
  for (const auto& p : cfg.plugins)
    if (p.library == "sim_world") return p.name;
  throw std::runtime_error("the configuration runs no sim_world: a trial needs the world's truth");
}

std::string fold_instance(const config::DaemonConfig& cfg) {
  for (const auto& p : cfg.plugins)
    if (p.library == "fold_sequence") return p.name;
  throw std::runtime_error("the configuration runs no fold_sequence");
}

// The port INSTANCE's port KEY is bound to (KEY itself when not remapped).
// Where two sheets' frames put the near half's centre apart (mm).
double frame_error_mm(const SheetState& a, const SheetState& b) {
  fold::SheetFrame fa, fb;
  if (!fold::sheet_frame(a, fa) || !fold::sheet_frame(b, fb)) return std::nan("");
  const double p[3] = {105.0, 74.25, 0.0};
  double pa[3], pb[3];
  fold::sheet_to_world(fa, p, pa);
  fold::sheet_to_world(fb, p, pb);
  return std::hypot(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]);
}

std::string port_of(const config::DaemonConfig& cfg, const std::string& instance, const std::string& key) {
  for (const auto& p : cfg.plugins)
    if (p.name == instance) {
      const auto it = p.ports.find(key);
      return it != p.ports.end() ? it->second : key;
    }
  return key;
}

// The world's hands now: touching anything, their lowest fingertip.
void hands_now(const WorldState& w, bool& touching, double& min_z) {
  touching = false;
  min_z = 1e9;
  for (const WorldHand& h : w.hand) {
    touching = touching || h.palm_contact != 0;
    for (const WorldFingertip& t : h.tip) {
      touching = touching || t.contact != 0 || t.normal_force_n > kTouchN;
      min_z = std::min(min_z, double(t.position_mm[2]));
    }
  }
}

}  // namespace

void enable_faults(config::DaemonConfig& cfg, std::uint64_t seed) {
  int worlds = 0;
  for (const auto& p : cfg.plugins) {
    if (p.library == "sim_world") {
      config::override_param(cfg, p.name + ".faults=true");
      config::override_param(cfg, p.name + ".fault_seed=" + std::to_string(seed));
      ++worlds;
    } else if (p.library == "camera_sim") {
      config::override_param(cfg, p.name + ".dropouts=3");
      config::override_param(cfg, p.name + ".dropout_seed=" + std::to_string(seed));
    }
  }
  if (worlds == 0) throw std::runtime_error("--faults: the configuration runs no sim_world (whose buses get the faults)");
}

void judge(TrialResult& r) {
  r.success = false;
  if (!r.error.empty()) {
    r.failure = "error: " + r.error;
  } else if (r.end != "done") {
    // The reason with the input it came from when the sequence named one: the why of its first
    // abort transition, "abort: device_fault: contact_r unhealthy".
    std::string reason = r.abort_reason;
    const std::string prefix = "abort: ";
    for (const TimelineEntry& e : r.timeline)
      if (!reason.empty() && e.why.rfind(prefix + reason, 0) == 0) {
        reason = e.why.substr(prefix.size());
        break;
      }
    r.failure = r.end == "not_started"
                    ? "not started (the start's guard never passed)"
                    : (r.end == "time_limit" ? "time limit in " : "aborted in ") +
                          r.last_fold_state + (reason.empty() ? "" : ": " + reason);
  } else if (!r.score.shape_ok) {
    r.failure = r.score.miss;
  } else if (!r.hands_clear) {
    r.failure = "a hand not clear of the sheet at the end";
  } else if (std::max(r.max_under_table_mm[0], r.max_under_table_mm[1]) > kUnderTableMm) {
    // The world's arms pass through the table; a real arm would have hit it.
    const int h = r.max_under_table_mm[0] >= r.max_under_table_mm[1] ? 0 : 1;
    char b[96];
    std::snprintf(b, sizeof b, "the %s arm %.1f mm under the table's top",
                  h == 0 ? "right" : "left", r.max_under_table_mm[h]);
    r.failure = b;
  } else {
    r.success = true;
    r.failure.clear();
    return;
  }
  // A failure whose fold was never made still says what the sheet's truth shows.
  if (r.error.empty() && !r.score.miss.empty() && r.end != "done") r.failure += "; sheet: " + r.score.miss;
}

TrialResult run_trial(const TrialOptions& o, int index, std::uint64_t seed) {
  TrialResult r;
  r.index = index;
  r.seed = seed;
  r.fold = o.fold;
  try {
    fs::create_directories(o.dir);
    config::DaemonConfig cfg = config::load_daemon_config(o.config);
    const std::string world = world_instance(cfg), fold = fold_instance(cfg);
    const std::string fold_file = "folds/" + o.fold + ".yaml";
    config::override_param(cfg, world + ".seed=" + std::to_string(seed));
    config::override_param(cfg, fold + ".fold=" + fold_file);
    if (o.faults) enable_faults(cfg, seed);
    const fold::FoldSpec spec = fold::load_fold_file((fs::path(cfg.file).parent_path() / fold_file).string());
    FoldTarget target;
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < 2; ++c) target.line_mm[k][c] = spec.fold_line_mm[k][c];
    target.flap_corner_mm[0] = spec.corner_mm[0];
    target.flap_corner_mm[1] = spec.corner_mm[1];
    r.draws = describe_draws(cfg);
    const std::string status_name = port_of(cfg, fold, "sequence_status");
    const std::string tracked_name =
        port_of(cfg, fold, "sheet_state");  // the model's sheet, as the sequence reads it
    // The hands' force controllers' status, as the sequence reads it.
    const std::string hand_status_name[2] = {port_of(cfg, fold, "hand_r_status"), port_of(cfg, fold, "hand_l_status")};
    const std::string contact_name[2] = {port_of(cfg, fold, "contact_r_state"),
                                         port_of(cfg, fold, "contact_l_state")};

    daemon::Options opts;
    opts.plugin_dirs = o.plugin_dirs;
    opts.report_dir = o.dir;
    opts.socket = (fs::path(o.dir) / "creased.sock").string();
    opts.progress = false;
    opts.duration_s = o.ready_timeout_s + o.max_fold_s + kAbortWaitS + o.retain_s + 30.0;  // a backstop only
    daemon::Daemon d(std::move(cfg), opts);
    PluginHost& host = d.host();
    auto status = reader<SequenceStatus>(host, status_name);
    auto world_state = reader<WorldState>(host, "world_state");
    std::unique_ptr<rt::LatestReader<HandControlStatus>> hand_status[2] = {
        reader<HandControlStatus>(host, hand_status_name[0]), reader<HandControlStatus>(host, hand_status_name[1])};
    std::unique_ptr<rt::LatestReader<ContactState>> contact_state[2] = {
        reader<ContactState>(host, contact_name[0]), reader<ContactState>(host, contact_name[1])};
    auto truth = reader<SheetState>(host, "sheet_truth");
    auto tracked = reader<SheetState>(host, tracked_name);
    auto reference = std::make_unique<SheetState>();
    auto start_truth = std::make_unique<SheetState>();  // the truth at the sequence's start
    bool have_start_truth = false;
    bool have_reference = false;
    std::atomic<bool> daemon_ended{false};  // run() returned (or threw) before the supervisor ended it

    // The supervisor: starts the sequence, follows it, takes the truth, ends the run.
    std::thread supervisor([&] {
      const std::int64_t t0 = rt::now_ns();
      auto since = [&](std::int64_t from) { return static_cast<double>(rt::now_ns() - from) * 1e-9; };
      host.set_param(fold, "command", 1.0);  // creasectl sequence start: taken when the guard passes
      std::int64_t started_ns = 0, ended_ns = 0, sampled_ns = 0;
      double window_force[2] = {0, 0};  // each hand's largest fingertip force since the last sample
      int window_tip[2] = {-1, -1};     // ... which fingertip, and its height then
      double window_tip_z[2] = {std::nan(""), std::nan("")};
      double window_measured[2] = {std::nan(""), std::nan("")};  // ... as its force controller measured it
      std::uint32_t seen_transitions = 0;
      std::set<std::string> fold_states;
      bool operator_abort = false, grasp_reference = false;
      for (;;) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        if (daemon_ended.load()) {
          r.end = "error";
          r.error = "creased stopped before the trial ended";
          break;
        }
        status->poll();
        const SequenceStatus& s = status->value();
        if (world_state->poll().has_data()) {
          for (int h = 0; h < 2; ++h)
            for (int f = 0; f < static_cast<int>(std::size(world_state->value().hand[h].tip));
                 ++f) {
              const WorldFingertip& t = world_state->value().hand[h].tip[f];
              if (t.normal_force_n > 0 && double(t.normal_force_n) > window_force[h]) {
                window_force[h] = t.normal_force_n;
                window_tip[h] = f;
                window_tip_z[h] = t.position_mm[2];
              }
            }
          for (int h = 0; h < 2; ++h) r.max_force_n[h] = std::max(r.max_force_n[h], window_force[h]);
          for (int h = 0; h < 2; ++h)
            r.max_under_table_mm[h] =
                std::max(r.max_under_table_mm[h], double(world_state->value().under_table_mm[h]));
        }
        for (int h = 0; h < 2; ++h)
          if (hand_status[h]->poll().has_data())
            for (float f : hand_status[h]->value().force_n)
              if (!(window_measured[h] >= f)) window_measured[h] = f;  // NaN (none yet) or less
        if (started_ns != 0 && rt::now_ns() - sampled_ns >= static_cast<std::int64_t>(kSeriesS * 1e9)) {
          sampled_ns = rt::now_ns();
          const double stretch = truth->poll().has_data() ? max_stretch(truth->value()) : std::nan("");
          SeriesSample x{since(started_ns),
                         {window_force[0], window_force[1]},
                         stretch,
                         {window_measured[0], window_measured[1]},
                         {window_tip[0], window_tip[1]},
                         {window_tip_z[0], window_tip_z[1]}};
          if (tracked->poll().has_data() && truth->poll().has_data())
            x.frame_err_mm = frame_error_mm(tracked->value(), truth->value());
          if (have_start_truth && truth->poll().has_data())
            x.frame_moved_mm = frame_error_mm(*start_truth, truth->value());
          if (world_state->poll().has_data())
            for (int h = 0; h < 2; ++h) {
              const WorldHand& wh = world_state->value().hand[h];
              x.ff_z_mm[h] = wh.tip[0].position_mm[2];
              x.palm_contact[h] = wh.palm_contact;
              x.wrist_deflection_deg[h] =
                  std::hypot(wh.deflection_rad[0], wh.deflection_rad[1]) * 180.0 / std::numbers::pi;
            }
          double g[3], gt[3];
          const bool world_grasp =
              truth->poll().has_data() &&
              fold::node_at(truth->value(), spec.grasp_at_mm[0], spec.grasp_at_mm[1], g);
          if (world_grasp) x.grasp_z_mm = g[2];
          if (tracked->poll().has_data()) {
            x.observations = static_cast<long>(tracked->value().observations);
            if (fold::node_at(tracked->value(), spec.grasp_at_mm[0], spec.grasp_at_mm[1], gt)) {
              x.grasp_tracked_z_mm = gt[2];
              if (world_grasp)
                x.grasp_off_mm = std::hypot(gt[0] - g[0], gt[1] - g[1], gt[2] - g[2]);
            }
          }
          for (int h = 0; h < 2; ++h)
            if (contact_state[h]->poll().has_data()) {
              const ContactState& c = contact_state[h]->value();
              x.contact_fingers[h] = c.in_contact != 0 ? c.fingers : 0;
              x.contact_onsets[h] = static_cast<long>(c.onsets);
            }
          r.series.push_back(x);
          window_force[0] = window_force[1] = 0;
          window_tip[0] = window_tip[1] = -1;
          window_tip_z[0] = window_tip_z[1] = std::nan("");
          window_measured[0] = window_measured[1] = std::nan("");
        }
        if (started_ns == 0 && s.phase != SequenceStatus::idle) {
          started_ns = rt::now_ns();
          if (truth->poll().has_data()) {
            *reference = truth->value();  // the slip's reference until the grasp
            have_reference = true;
            *start_truth = truth->value();
            have_start_truth = true;
          }
        }
        if (s.transitions != seen_transitions) {
          seen_transitions = s.transitions;
          const std::string path(s.path, strnlen(s.path, sizeof s.path));
          r.timeline.push_back({started_ns != 0 ? since(started_ns) : 0.0, path, std::string(s.why, strnlen(s.why, sizeof s.why))});
          if (path.rfind("fold/", 0) == 0) {
            fold_states.insert(path);
            r.last_fold_state = path;
          }
          if (!grasp_reference && path.rfind("fold/grasp", 0) == 0 && truth->poll().has_data()) {
            *reference = truth->value();  // the shift is over: from here on the base should stay
            have_reference = grasp_reference = true;
          }
        }
        if (started_ns == 0) {
          if (since(t0) > o.ready_timeout_s) {
            r.end = "not_started";
            break;
          }
          continue;
        }
        // Aborted once the retreat ended (the phase is `aborted` while it runs, under abort/).
        const bool retreat_over = std::strncmp(s.path, "aborted", sizeof s.path) == 0;
        if (s.phase == SequenceStatus::done || (s.phase == SequenceStatus::aborted && retreat_over)) {
          if (ended_ns == 0) ended_ns = rt::now_ns();
          const bool retained = s.phase != SequenceStatus::done || since(ended_ns) >= o.retain_s;
          if (retained && since(ended_ns) >= 0.5) {
            r.end = s.phase == SequenceStatus::done ? "done" : (operator_abort ? "time_limit" : "aborted");
            r.abort_reason = s.phase == SequenceStatus::aborted
                                 ? fold::reason_name(static_cast<fold::Reason>(s.abort_reason))
                                 : "";
            r.fold_time_s = static_cast<double>(ended_ns - started_ns) * 1e-9;
            break;
          }
          continue;
        }
        // The time limit: the operator aborts a fold still running (one that aborted by itself
        // is retreating already and keeps its own reason); any retreat gets kAbortWaitS more.
        if (!operator_abort && s.phase != SequenceStatus::aborted &&
            since(started_ns) > o.max_fold_s) {
          host.set_param(fold, "command", 4.0);  // creasectl sequence abort: the safe retreat
          operator_abort = true;
        }
        if (since(started_ns) > o.max_fold_s + kAbortWaitS) {
          r.end = "time_limit";
          r.error = "the abort's retreat did not end";
          break;
        }
      }
      status->poll();
      r.transitions = status->value().transitions;
      r.fold_states = static_cast<int>(fold_states.size());
      if (world_state->poll().has_data()) {
        bool touching = false;
        hands_now(world_state->value(), touching, r.min_tip_z_mm);
        r.hands_clear = !touching && r.min_tip_z_mm >= kClearMm;
      }
      // The sheet as it lies now, from a sample taken after the end.
      const std::int64_t at = rt::now_ns();
      while (truth->poll().has_data() && truth->value().timestamp_ns < at && since(at) < 2.0)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (truth->poll().has_data()) {
        const SheetState& end = truth->value();
        r.score = score_sheet(end, target, o.bounds, have_reference ? reference.get() : nullptr);
        if (static_cast<std::uint32_t>(end.nodes_u) * end.nodes_v <= SheetState::kMaxNodes) {
          r.sheet_nodes_u = end.nodes_u;
          r.sheet_nodes_v = end.nodes_v;
          for (int k = 0; k < end.nodes_u * end.nodes_v; ++k)
            r.sheet_end_mm.push_back(
                {end.position_mm[k][0], end.position_mm[k][1], end.position_mm[k][2]});
        }
      }
      d.request_stop();
    });
    try {
      d.run();
    } catch (...) {
      daemon_ended.store(true);
      supervisor.join();
      throw;
    }
    daemon_ended.store(true);
    supervisor.join();
    // The exact timeline: every transition the sequence marked (the host's events), sampled
    // above only as a fallback. Times from its start; the fold's time from start to its end.
    std::vector<TimelineEntry> marks;
    std::set<std::string> states;
    std::int64_t t_start = 0, t_end = 0;
    std::string last;
    for (const HostEvent& e : host.events()) {
      if (e.type != HostEvent::Type::mark || e.instance != fold) continue;
      const std::size_t colon = e.detail.find(": ");
      const std::string path = e.detail.substr(0, colon), why = colon == std::string::npos ? "" : e.detail.substr(colon + 2);
      if (t_start == 0) t_start = e.time_ns;
      marks.push_back({static_cast<double>(e.time_ns - t_start) * 1e-9, path, why});
      if (path.rfind("fold/", 0) == 0) {
        states.insert(path);
        last = path;
      }
      if (path == "aborted" || path == "done") t_end = e.time_ns;
    }
    if (!marks.empty()) {
      r.timeline = std::move(marks);
      r.fold_states = static_cast<int>(states.size());
      r.last_fold_state = last;
      if (t_end != 0) r.fold_time_s = static_cast<double>(t_end - t_start) * 1e-9;
    }
  } catch (const std::exception& e) {
    r.error = e.what();
    r.end = "error";
  }
  judge(r);
  return r;
}

}  // namespace crease::trials
