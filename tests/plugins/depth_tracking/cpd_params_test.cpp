// cpd_params_from: the plugin's CPD parameters, with file, line and key in every error.
#include "plugins/depth_tracking/cpd_params.h"

#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "core/errors.h"

namespace {

crease::Params params(const std::string& yaml) {
  return crease::Params(YAML::Load(yaml), "depth.yaml", "plugins[3].params");
}

std::string error_of(const std::string& yaml) {
  try {
    (void)crease::depth::cpd_params_from(params(yaml));
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("defaults and given values") {
  const auto d = crease::depth::cpd_params_from(params("{}"));
  CHECK(d.beta_mm == doctest::Approx(40.0));
  const auto c = crease::depth::cpd_params_from(params("{beta_mm: 25, lambda: 3, w: 0.2}"));
  CHECK(c.beta_mm == doctest::Approx(25.0));
  CHECK(c.lambda == doctest::Approx(3.0));
  CHECK(c.w == doctest::Approx(0.2));
}

TEST_CASE("out-of-range beta, lambda and w name the file and the key") {
  for (const char* key : {"beta_mm", "lambda", "w"}) {
    const std::string e = error_of(std::string("{") + key + ": 5000}");
    INFO(e);
    CHECK(e.find("depth.yaml") != std::string::npos);
    CHECK(e.find(std::string(key)) != std::string::npos);
  }
  CHECK(error_of("{beta_mm: 0.1}").find("beta_mm") != std::string::npos);
  CHECK(error_of("{lambda: 0}").find("lambda") != std::string::npos);
  CHECK(error_of("{w: -0.1}").find(".w") != std::string::npos);
}
