// JSON (nlohmann) conversion of the report model, both ways: the daemon may send a report
// over the control socket and creasectl render it, or a script may read the JSON file.
#pragma once

#include <nlohmann/json.hpp>

#include "core/report/timing_report.h"

namespace crease::report {

void to_json(nlohmann::json& j, const Bucket& v);
void from_json(const nlohmann::json& j, Bucket& v);
void to_json(nlohmann::json& j, const CycleSample& v);
void from_json(const nlohmann::json& j, CycleSample& v);
void to_json(nlohmann::json& j, const Distribution& v);
void from_json(const nlohmann::json& j, Distribution& v);
void to_json(nlohmann::json& j, const PluginTiming& v);
void from_json(const nlohmann::json& j, PluginTiming& v);
void to_json(nlohmann::json& j, const LoopTiming& v);
void from_json(const nlohmann::json& j, LoopTiming& v);
void to_json(nlohmann::json& j, const Event& v);
void from_json(const nlohmann::json& j, Event& v);
void to_json(nlohmann::json& j, const FigureSummary& v);
void from_json(const nlohmann::json& j, FigureSummary& v);
void to_json(nlohmann::json& j, const PortTraffic& v);
void from_json(const nlohmann::json& j, PortTraffic& v);
void to_json(nlohmann::json& j, const ThreadPlacement& v);
void from_json(const nlohmann::json& j, ThreadPlacement& v);
void to_json(nlohmann::json& j, const MachineInfo& v);
void from_json(const nlohmann::json& j, MachineInfo& v);
void to_json(nlohmann::json& j, const TimingReport& v);
// @throws nlohmann::json::exception on a missing or mistyped field.
void from_json(const nlohmann::json& j, TimingReport& v);

}  // namespace crease::report
