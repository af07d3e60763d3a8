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
}  // namespace

nlohmann::json to_json(const TrialResult& r) {
  nlohmann::json timeline = nlohmann::json::array();
  for (const auto& e : r.timeline)
    timeline.push_back({{"t_s", e.t_s}, {"path", e.path}, {"why", e.why}});
  nlohmann::json series = {{"t_s", nlohmann::json::array()},
                           {"force_r_n", nlohmann::json::array()},
                           {"force_l_n", nlohmann::json::array()},
                           {"stretch", nlohmann::json::array()},
                           {"measured_r_n", nlohmann::json::array()},
                           {"measured_l_n", nlohmann::json::array()},
                           {"tip_r", nlohmann::json::array()},
                           {"tip_l", nlohmann::json::array()},
                           {"tip_r_z_mm", nlohmann::json::array()},
                           {"tip_l_z_mm", nlohmann::json::array()},
                           {"contact_r", nlohmann::json::array()},
                           {"contact_l", nlohmann::json::array()},
                           {"onsets_r", nlohmann::json::array()},
                           {"onsets_l", nlohmann::json::array()},
                           {"frame_mm", nlohmann::json::array()},
                           {"grasp_z_mm", nlohmann::json::array()},
                           {"grasp_tracked_z_mm", nlohmann::json::array()},
                           {"grasp_off_mm", nlohmann::json::array()},
                           {"observations", nlohmann::json::array()},
                           {"frame_moved_mm", nlohmann::json::array()},
                           {"ff_r_z_mm", nlohmann::json::array()},
                           {"ff_l_z_mm", nlohmann::json::array()},
                           {"palm_r", nlohmann::json::array()},
                           {"palm_l", nlohmann::json::array()},
                           {"wrist_r_deg", nlohmann::json::array()},
                           {"wrist_l_deg", nlohmann::json::array()}};
  nlohmann::json sheet_end = {{"nodes_u", r.sheet_nodes_u},
                              {"nodes_v", r.sheet_nodes_v},
                              {"position_mm", nlohmann::json::array()}};
  for (const auto& p : r.sheet_end_mm) sheet_end["position_mm"].push_back({p[0], p[1], p[2]});
  for (const auto& x : r.series) {
    series["t_s"].push_back(x.t_s);
    series["force_r_n"].push_back(num(x.force_n[0]));
    series["force_l_n"].push_back(num(x.force_n[1]));
    series["stretch"].push_back(num(x.stretch));
    series["measured_r_n"].push_back(num(x.measured_n[0]));
    series["measured_l_n"].push_back(num(x.measured_n[1]));
    series["tip_r"].push_back(x.force_tip[0]);
    series["tip_l"].push_back(x.force_tip[1]);
    series["tip_r_z_mm"].push_back(num(x.force_tip_z_mm[0]));
    series["tip_l_z_mm"].push_back(num(x.force_tip_z_mm[1]));
    series["contact_r"].push_back(x.contact_fingers[0]);
    series["contact_l"].push_back(x.contact_fingers[1]);
    series["frame_mm"].push_back(num(x.frame_err_mm));
    series["frame_moved_mm"].push_back(num(x.frame_moved_mm));
    series["ff_r_z_mm"].push_back(num(x.ff_z_mm[0]));
    series["ff_l_z_mm"].push_back(num(x.ff_z_mm[1]));
    series["palm_r"].push_back(x.palm_contact[0]);
    series["palm_l"].push_back(x.palm_contact[1]);
    series["wrist_r_deg"].push_back(num(x.wrist_deflection_deg[0]));
    series["wrist_l_deg"].push_back(num(x.wrist_deflection_deg[1]));
    series["grasp_z_mm"].push_back(num(x.grasp_z_mm));
    series["grasp_tracked_z_mm"].push_back(num(x.grasp_tracked_z_mm));
    series["grasp_off_mm"].push_back(num(x.grasp_off_mm));
    series["observations"].push_back(x.observations);
    series["onsets_r"].push_back(x.contact_onsets[0]);
    series["onsets_l"].push_back(x.contact_onsets[1]);
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
      SeriesSample v{x.at("t_s")[k].get<double>(),
                     {num(x.at("force_r_n")[k]), num(x.at("force_l_n")[k])},
                     num(x.at("stretch")[k])};
      if (x.contains("measured_r_n")) v.measured_n[0] = num(x.at("measured_r_n")[k]);
      if (x.contains("measured_l_n")) v.measured_n[1] = num(x.at("measured_l_n")[k]);
      if (x.contains("tip_r")) {
        v.force_tip[0] = x.at("tip_r")[k].get<int>();
        v.force_tip[1] = x.at("tip_l")[k].get<int>();
        v.force_tip_z_mm[0] = num(x.at("tip_r_z_mm")[k]);
        v.force_tip_z_mm[1] = num(x.at("tip_l_z_mm")[k]);
      }
      if (x.contains("frame_mm")) v.frame_err_mm = num(x.at("frame_mm")[k]);
      if (x.contains("frame_moved_mm")) v.frame_moved_mm = num(x.at("frame_moved_mm")[k]);
      if (x.contains("ff_r_z_mm")) {
        v.ff_z_mm[0] = num(x.at("ff_r_z_mm")[k]);
        v.ff_z_mm[1] = num(x.at("ff_l_z_mm")[k]);
      }
      if (x.contains("palm_r")) {
        v.palm_contact[0] = x.at("palm_r")[k].get<int>();
        v.palm_contact[1] = x.at("palm_l")[k].get<int>();
        v.wrist_deflection_deg[0] = num(x.at("wrist_r_deg")[k]);
        v.wrist_deflection_deg[1] = num(x.at("wrist_l_deg")[k]);
      }
      if (x.contains("grasp_z_mm")) {
        v.grasp_z_mm = num(x.at("grasp_z_mm")[k]);
        v.grasp_tracked_z_mm = num(x.at("grasp_tracked_z_mm")[k]);
      }
      if (x.contains("grasp_off_mm")) {
        v.grasp_off_mm = num(x.at("grasp_off_mm")[k]);
        v.observations = x.at("observations")[k].get<long>();
      }
      if (x.contains("contact_r")) {
        v.contact_fingers[0] = x.at("contact_r")[k].get<int>();
        v.contact_fingers[1] = x.at("contact_l")[k].get<int>();
        v.contact_onsets[0] = x.at("onsets_r")[k].get<long>();
        v.contact_onsets[1] = x.at("onsets_l")[k].get<long>();
      }
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
