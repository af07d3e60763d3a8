// CpdParams from a plugin's parameters (keys as the fields of CpdParams): every value out of
// range is a crease::ConfigError naming the file, line and key (Params::get_in_range).
#pragma once

#include "core/params.h"
#include "plugins/depth_tracking/cpd.h"

namespace crease::depth {

CpdParams cpd_params_from(const crease::Params& p);

}  // namespace crease::depth
