// For tests that add plugin instances to a PluginHost by hand: the spec of one instance.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "core/params.h"
#include "core/plugin_host.h"

namespace crease::testing {

// Instance NAME of plugin LIBRARY in LOOP at ORDER, its parameters the YAML flow map PARAMS read
// as if from config/test.yaml (relative paths resolve against config/; errors name
// "NAME.params").
inline InstanceSpec instance_spec(const std::string& name, const std::string& library,
                                  const std::string& loop, int order, const std::string& params) {
  InstanceSpec s;
  s.name = name;
  s.library = library;
  s.loop = loop;
  s.order = order;
  s.params = Params(YAML::Load(params), std::string(CREASE_SOURCE_DIR) + "/config/test.yaml",
                    name + ".params");
  return s;
}

}  // namespace crease::testing
