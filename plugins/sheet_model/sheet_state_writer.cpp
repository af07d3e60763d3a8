#include "sheet_state_writer.h"

#include <algorithm>

namespace crease::sheet {

void write_sheet_state(const SheetModel& m, std::span<Vec3> normals, std::span<double> strain, std::int64_t now_ns,
                       std::uint64_t step, SheetState& out) noexcept {
  const Grid& g = m.grid();
  out.timestamp_ns = now_ns;
  out.step = step;
  out.nodes_u = static_cast<std::uint16_t>(g.w);
  out.nodes_v = static_cast<std::uint16_t>(g.h);
  out.width_mm = static_cast<float>(g.width_mm);
  out.height_mm = static_cast<float>(g.height_mm);
  m.compute_normals(normals);
  const auto x = m.positions();
  const int n = std::min<int>(g.count(), SheetState::kMaxNodes);
  for (int i = 0; i < n; ++i) {
    out.position_mm[i][0] = static_cast<float>(x[i].x);
    out.position_mm[i][1] = static_cast<float>(x[i].y);
    out.position_mm[i][2] = static_cast<float>(x[i].z);
    out.normal[i][0] = static_cast<float>(normals[i].x);
    out.normal[i][1] = static_cast<float>(normals[i].y);
    out.normal[i][2] = static_cast<float>(normals[i].z);
  }
  m.compute_strains(strain);
  out.link_count = static_cast<std::uint32_t>(std::min<int>(m.link_count(), SheetState::kMaxLinks));
  for (std::uint32_t k = 0; k < out.link_count; ++k) out.strain[k] = static_cast<float>(strain[k]);
  out.crease_count = 0;
  const CreaseSet& cs = m.creases();
  for (int c = 0; c < CreaseSet::kCapacity && out.crease_count < SheetState::kMaxCreases; ++c) {
    if (!cs.used(c)) continue;
    const CreaseLine& l = cs.line(c);
    out.crease_id[out.crease_count] = c;
    float* o = out.crease_mm[out.crease_count++];
    o[0] = static_cast<float>(l.a.u);
    o[1] = static_cast<float>(l.a.v);
    o[2] = static_cast<float>(l.b.u);
    o[3] = static_cast<float>(l.b.v);
  }
}

}  // namespace crease::sheet
