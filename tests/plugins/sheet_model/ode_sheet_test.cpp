// The shared behaviour tests against the ODE backend.
#include "plugins/sheet_model/ode_sheet.h"

#include "sheet_behaviour.h"

std::unique_ptr<crease::sheet::SheetModel> sheet_behaviour::make_sheet(const crease::sheet::SheetParams& p) {
  return std::make_unique<crease::sheet::OdeSheet>(p, 10, 3);  // 3 ODE steps per frame: test time
}
