#include "tools/trials/trial_json.h"

#include <cmath>
#include <string>

namespace crease::trials {

namespace {
nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
double num(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : std::nan("");
}
nlohmann::json value(double v) {
  return num(v);
}
nlohmann::json value(long v) {
  return v;
}
nlohmann::json value(int v) {
  return v;
}
void read(const nlohmann::json& j, double& v) {
  v = num(j);
}
void read(const nlohmann::json& j, long& v) {
  v = j.get<long>();
}
void read(const nlohmann::json& j, int& v) {
  v = j.get<int>();
}

// The series' value columns beside its time axis "t_s", each once: f(group, name, field) for
// every field of sample X (a SeriesSample, const when written). A column is read when its group's
// first column is in the file (results written before the group: the sample's defaults), and then
// must be there; the first group ("t_s") always.
template <class Sample, class F>
void for_each_column(Sample& x, F&& f) {
  f("t_s", "force_r_n", x.force_n[0]);
  f("t_s", "force_l_n", x.force_n[1]);
  f("t_s", "stretch", x.stretch);
  f("measured_r_n", "measured_r_n", x.measured_n[0]);
  f("measured_l_n", "measured_l_n", x.measured_n[1]);
  f("tip_r", "tip_r", x.force_tip[0]);
  f("tip_r", "tip_l", x.force_tip[1]);
  f("tip_r", "tip_r_z_mm", x.force_tip_z_mm[0]);
  f("tip_r", "tip_l_z_mm", x.force_tip_z_mm[1]);
  f("frame_mm", "frame_mm", x.frame_err_mm);
  f("frame_moved_mm", "frame_moved_mm", x.frame_moved_mm);
  f("ff_r_z_mm", "ff_r_z_mm", x.ff_z_mm[0]);
  f("ff_r_z_mm", "ff_l_z_mm", x.ff_z_mm[1]);
  f("palm_r", "palm_r", x.palm_contact[0]);
  f("palm_r", "palm_l", x.palm_contact[1]);
  f("palm_r", "wrist_r_deg", x.wrist_deflection_deg[0]);
  f("palm_r", "wrist_l_deg", x.wrist_deflection_deg[1]);
  f("grasp_z_mm", "grasp_z_mm", x.grasp_z_mm);
  f("grasp_z_mm", "grasp_tracked_z_mm", x.grasp_tracked_z_mm);
  f("grasp_off_mm", "grasp_off_mm", x.grasp_off_mm);
  f("grasp_off_mm", "observations", x.observations);
  f("contact_r", "contact_r", x.contact_fingers[0]);
  f("contact_r", "contact_l", x.contact_fingers[1]);
  f("contact_r", "onsets_r", x.contact_onsets[0]);
  f("contact_r", "onsets_l", x.contact_onsets[1]);
}
}  // namespace

nlohmann::json to_json(const TrialResult& r) {
  nlohmann::json timeline = nlohmann::json::array();
  for (const auto& e : r.timeline)
    timeline.push_back({{"t_s", e.t_s}, {"path", e.path}, {"why", e.why}});
  nlohmann::json series = {{"t_s", nlohmann::json::array()}};
  const SeriesSample none;
  for_each_column(none, [&](const char*, const char* name, const auto&) {
    series[name] = nlohmann::json::array();
  });
  nlohmann::json sheet_end = {{"nodes_u", r.sheet_nodes_u},
                              {"nodes_v", r.sheet_nodes_v},
                              {"position_mm", nlohmann::json::array()}};
  for (const auto& p : r.sheet_end_mm) sheet_end["position_mm"].push_back({p[0], p[1], p[2]});
  for (const auto& x : r.series) {
    series["t_s"].push_back(x.t_s);
    for_each_column(
        x, [&](const char*, const char* name, const auto& v) { series[name].push_back(value(v)); });
  }
  const Score& s = r.score;
  return {{"trial", r.index},
          {"seed", r.seed},
          {"fold", r.fold},
          {"draws", r.draws},
          {"end", r.end},
          {"abort_reason", r.abort_reason},
          {"last_fold_state", r.last_fold_state},
          {"fold_states", r.fold_states},
          {"transitions", r.transitions},
          {"fold_time_s", r.fold_time_s},
          {"score",
           {{"fold_line_mm", num(s.fold_line_mm)},
            {"fold_angle_deg", num(s.fold_angle_deg)},
            {"corners_mm", num(s.corners_mm)},
            {"retained_deg", num(s.retained_deg)},
            {"max_stretch", num(s.max_stretch)},
            {"stretch_at_mm", {num(s.stretch_at_mm[0]), num(s.stretch_at_mm[1])}},
            {"slip_mm", num(s.slip_mm)},
            {"flap_nodes", s.flap_nodes},
            {"folded_nodes", s.folded_nodes},
            {"base_nodes", s.base_nodes},
            {"torn", s.torn},
            {"off_table", s.off_table},
            {"valid", s.valid},
            {"shape_ok", s.shape_ok},
            {"miss", s.miss}}},
          {"hands_clear", r.hands_clear},
          {"min_tip_z_mm", num(r.min_tip_z_mm)},
          {"max_force_n", {num(r.max_force_n[0]), num(r.max_force_n[1])}},
          {"max_under_table_mm", {num(r.max_under_table_mm[0]), num(r.max_under_table_mm[1])}},
          {"success", r.success},
          {"failure", r.failure},
          {"timeline", timeline},
          {"series", series},
          {"sheet_end", sheet_end},
          {"error", r.error}};
}

TrialResult from_json(const nlohmann::json& j) {
  TrialResult r;
  r.index = j.at("trial").get<int>();
  r.seed = j.at("seed").get<std::uint64_t>();
  r.fold = j.at("fold").get<std::string>();
  r.draws = j.at("draws").get<std::string>();
  r.end = j.at("end").get<std::string>();
  r.abort_reason = j.at("abort_reason").get<std::string>();
  r.last_fold_state = j.at("last_fold_state").get<std::string>();
  r.fold_states = j.at("fold_states").get<int>();
  r.transitions = j.at("transitions").get<std::uint32_t>();
  r.fold_time_s = j.at("fold_time_s").get<double>();
  const auto& s = j.at("score");
  r.score.fold_line_mm = num(s.at("fold_line_mm"));
  r.score.fold_angle_deg = num(s.at("fold_angle_deg"));
  r.score.corners_mm = num(s.at("corners_mm"));
  r.score.retained_deg = num(s.at("retained_deg"));
  r.score.max_stretch = num(s.at("max_stretch"));
  if (s.contains("stretch_at_mm")) {
    r.score.stretch_at_mm[0] = num(s.at("stretch_at_mm")[0]);
    r.score.stretch_at_mm[1] = num(s.at("stretch_at_mm")[1]);
  }
  r.score.slip_mm = num(s.at("slip_mm"));
  r.score.flap_nodes = s.at("flap_nodes").get<int>();
  r.score.folded_nodes = s.at("folded_nodes").get<int>();
  r.score.base_nodes = s.at("base_nodes").get<int>();
  r.score.torn = s.at("torn").get<bool>();
  r.score.off_table = s.at("off_table").get<bool>();
  r.score.valid = s.at("valid").get<bool>();
  r.score.shape_ok = s.at("shape_ok").get<bool>();
  r.score.miss = s.at("miss").get<std::string>();
  r.hands_clear = j.at("hands_clear").get<bool>();
  r.min_tip_z_mm = num(j.at("min_tip_z_mm"));
  r.max_force_n[0] = num(j.at("max_force_n")[0]);
  r.max_force_n[1] = num(j.at("max_force_n")[1]);
  if (j.contains("max_under_table_mm")) {  // results written before it: 0
    r.max_under_table_mm[0] = num(j.at("max_under_table_mm")[0]);
    r.max_under_table_mm[1] = num(j.at("max_under_table_mm")[1]);
  }
  r.success = j.at("success").get<bool>();
  r.failure = j.at("failure").get<std::string>();
  for (const auto& e : j.at("timeline"))
    r.timeline.push_back({e.at("t_s").get<double>(), e.at("path").get<std::string>(),
                          e.at("why").get<std::string>()});
  if (j.contains("series")) {
    const auto& x = j.at("series");
    for (std::size_t k = 0; k < x.at("t_s").size(); ++k) {
      SeriesSample v;
      v.t_s = x.at("t_s")[k].get<double>();
      for_each_column(v, [&](const char* group, const char* name, auto& field) {
        if (x.contains(group)) read(x.at(name)[k], field);
      });
      r.series.push_back(v);
    }
  }
  if (j.contains("sheet_end")) {
    const auto& e = j.at("sheet_end");
    r.sheet_nodes_u = e.at("nodes_u").get<int>();
    r.sheet_nodes_v = e.at("nodes_v").get<int>();
    for (const auto& p : e.at("position_mm"))
      r.sheet_end_mm.push_back({p[0].get<float>(), p[1].get<float>(), p[2].get<float>()});
  }
  r.error = j.at("error").get<std::string>();
  return r;
}

}  // namespace crease::trials
