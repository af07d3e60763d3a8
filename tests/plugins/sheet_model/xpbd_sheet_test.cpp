// The shared behaviour tests against the XPBD backend.
#include "plugins/sheet_model/xpbd_sheet.h"

#include <algorithm>
#include <limits>

#include "sheet_behaviour.h"

std::unique_ptr<crease::sheet::SheetModel> sheet_behaviour::make_sheet(const crease::sheet::SheetParams& p) {
  return std::make_unique<crease::sheet::XpbdSheet>(p);
}
