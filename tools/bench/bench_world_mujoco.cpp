// crease-bench world, the peer: MuJoCo 2.2.2 (Debian libmujoco-dev) simulating the same scene.
//
// The sheet is MuJoCo's 2-D composite grid (`<composite type="grid">`: one sphere particle per
// node with three slide joints, neighbours joined by tendons held at length by soft equality
// constraints), of the same node count and spacing and the same mass; the table is a plane;
// every hand shape of our run is a mocap body of the same geometry following the same poses,
// one per step, so both simulators see the same hands on the same paths with the same 1 ms
// step. Friction: MuJoCo takes the larger of two geoms' coefficients, so the particles carry
// none and each shape and the table carry the paper's coefficient against them.
// The particles are spheres of `particle_radius_mm` (MuJoCo needs a volume to collide), their
// centres half the sheet's thickness over the table top (the plane is lowered by the rest).
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "bench_world_scene.h"

namespace crease::bench::world_scene {

namespace {

const char* geom_type(world::GeomKind k) {
  switch (k) {
    case world::GeomKind::sphere: return "sphere";
    case world::GeomKind::capsule: return "capsule";
    case world::GeomKind::cylinder: return "cylinder";
    case world::GeomKind::box: return "box";
  }
  return "sphere";
}

std::string geom_size_m(const world::Geom& g) {
  std::ostringstream s;
  switch (g.kind) {
    case world::GeomKind::sphere: s << g.radius_mm / 1000; break;
    case world::GeomKind::capsule:
    case world::GeomKind::cylinder: s << g.radius_mm / 1000 << ' ' << g.half_length_mm / 1000; break;
    case world::GeomKind::box: s << g.half_mm.x / 1000 << ' ' << g.half_mm.y / 1000 << ' ' << g.half_mm.z / 1000; break;
  }
  return s.str();
}

std::string scene_xml(const Script& scene, const std::vector<MirroredShape>& shapes, double table_friction,
                      const MujocoOptions& o) {
  const sheet::GridParams& g = scene.params.sheet.grid;
  const int nodes_u = g.nodes_u, nodes_v = g.nodes_v;
  const double spacing_mm = g.width_mm / (nodes_u - 1);
  const double sheet_mass_kg = g.areal_density_g_per_m2 * 1e-3 * g.width_mm * g.height_mm * 1e-6;
  const double r = o.particle_radius_mm / 1000;
  const double half_thickness = o.sheet_thickness_mm / 2000;
  const double particle_mass = sheet_mass_kg / (nodes_u * nodes_v);
  const double top = -(r - half_thickness);  // the table top (m)
  // A finite table (the pinch's near edge) as a box, else a plane.
  std::ostringstream table;
  const auto& e = scene.params.table_extent_mm;
  const double lim = 1000.0;  // mm: "no edge" becomes a 1 m margin
  const double x0 = std::max(e[0], -lim), x1 = std::min(e[1], lim), y0 = std::max(e[2], -lim), y1 = std::min(e[3], lim);
  const bool finite = x0 > -lim || x1 < lim || y0 > -lim || y1 < lim;
  if (finite) {
    table << "type='box' pos='" << (x0 + x1) / 2000 << ' ' << (y0 + y1) / 2000 << ' ' << top - 0.01 << "' size='"
          << (x1 - x0) / 2000 << ' ' << (y1 - y0) / 2000 << " 0.01'";
  } else {
    table << "type='plane' pos='0 0 " << top << "' size='1 1 0.01'";
  }
  std::ostringstream x;
  x << "<mujoco model='crease_bench_world'>\n"
    << "  <option timestep='" << scene.params.dt_s << "' gravity='0 0 -9.81' jacobian='sparse' solver='" << o.solver
    << "' iterations='" << o.iterations << "' tolerance='" << o.tolerance << "'/>\n"
    << "  <size nconmax='" << nodes_u * nodes_v + 800 << "' njmax='" << 7 * nodes_u * nodes_v + 1500 << "'/>\n"
    << "  <worldbody>\n"
    << "    <geom name='table' " << table.str() << " friction='" << table_friction << " 0.005 0.0001'/>\n";
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const MirroredShape& s = shapes[i];
    x << "    <body name='shape" << i << "' mocap='true'><geom type='" << geom_type(s.geom.kind) << "' size='"
      << geom_size_m(s.geom) << "' friction='" << s.friction << " 0.005 0.0001'/></body>\n";
  }
  x << "    <composite type='grid' count='" << nodes_u << ' ' << nodes_v << " 1' spacing='" << spacing_mm / 1000
    << "' offset='0 0 " << half_thickness << "'>\n"
    << "      <geom size='" << r << "' mass='" << particle_mass << "' friction='0 0 0'/>\n"
    << "      <joint kind='main' damping='0.0001'/>\n"
    << "      <tendon kind='main' width='0.0005'/>\n"
    << "    </composite>\n"
    << "  </worldbody>\n"
    << "</mujoco>\n";
  return x.str();
}

void set_mocap(const mjModel* m, mjData* d, int body, const world::Pose& p) {
  const int id = m->body_mocapid[body];
  d->mocap_pos[3 * id + 0] = p.t.x / 1000;
  d->mocap_pos[3 * id + 1] = p.t.y / 1000;
  d->mocap_pos[3 * id + 2] = p.t.z / 1000;
  mjtNum mat[9];
  for (int k = 0; k < 9; ++k) mat[k] = p.r[k];
  mju_mat2Quat(d->mocap_quat + 4 * id, mat);
}

void sheet_nodes(const mjModel* m, const mjData* d, std::vector<sheet::Vec3>& out) {
  out.clear();
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_mocapid[b] >= 0) continue;
    out.push_back({1000 * d->xpos[3 * b], 1000 * d->xpos[3 * b + 1], 1000 * d->xpos[3 * b + 2]});
  }
}

}  // namespace

bool run_mujoco(const Script& scene, const std::vector<MirroredShape>& shapes, double table_friction,
                const MujocoOptions& o, SheetRun& out) {
  const std::string xml = scene_xml(scene, shapes, table_friction, o);
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  if (mj_makeEmptyFileVFS(&vfs, "scene.xml", static_cast<int>(xml.size())) != 0) return false;
  const int f = mj_findFileVFS(&vfs, "scene.xml");
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs.filedata[f]));
  char err[1000] = "";
  mjModel* m = mj_loadXML("scene.xml", &vfs, err, sizeof err);
  mj_deleteVFS(&vfs);
  if (m == nullptr) {
    std::printf("mujoco: the model was refused: %s\n", err);
    return false;
  }
  mjData* d = mj_makeData(m);
  if (d == nullptr) {
    std::printf("mujoco: no mjData for the model\n");
    mj_deleteModel(m);
    return false;
  }
  // Shape i is body i + 1 (declared first, after the world body).
  for (std::size_t i = 0; i < shapes.size(); ++i) set_mocap(m, d, static_cast<int>(i) + 1, shapes[i].poses.front());
  mj_forward(m, d);
  sheet_nodes(m, d, out.start);

  const std::size_t steps = shapes.empty() ? 0 : shapes.front().poses.size();
  double wall = 0;
  for (std::size_t k = 0; k < steps; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < shapes.size(); ++i) set_mocap(m, d, static_cast<int>(i) + 1, shapes[i].poses[k]);
    mj_step(m, d);
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (k == scene.mark_step) sheet_nodes(m, d, out.mark);
    if (scene.mark2_step != 0 && k == scene.mark2_step) sheet_nodes(m, d, out.mark2);
  }
  out.wall_s = wall;
  out.simulated_s = static_cast<double>(steps) * scene.params.dt_s;
  sheet_nodes(m, d, out.end);
  out.lowest_z_mm = 1e9;
  for (const sheet::Vec3& p : out.end) out.lowest_z_mm = std::min(out.lowest_z_mm, p.z);
  int warnings = 0;
  for (const mjWarningStat& w : d->warning) warnings += w.number;
  if (warnings > 0) std::printf("mujoco: %d warnings (buffers, instabilities) during the run\n", warnings);
  mj_deleteData(d);
  mj_deleteModel(m);
  return true;
}

}  // namespace crease::bench::world_scene
