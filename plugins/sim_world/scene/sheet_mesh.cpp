#include "plugins/sim_world/scene/sheet_mesh.h"

#include <algorithm>
#include <cmath>

namespace crease::vision {

cv::Vec3d SheetMesh::world_at(double u, double v) const {
  const double du = w_mm / (nx - 1), dv = h_mm / (ny - 1);
  const double fu = std::clamp(u / du, 0.0, nx - 1.0), fv = std::clamp(v / dv, 0.0, ny - 1.0);
  const int i = std::min(static_cast<int>(fu), nx - 2), j = std::min(static_cast<int>(fv), ny - 2);
  const double a = fu - i, b = fv - j;
  if (a + b <= 1.0)  // triangle (i,j)(i+1,j)(i,j+1)
    return node(i, j) + a * (node(i + 1, j) - node(i, j)) + b * (node(i, j + 1) - node(i, j));
  // triangle (i+1,j)(i+1,j+1)(i,j+1): barycentric from the (i+1,j+1) corner
  return node(i + 1, j + 1) + (1 - a) * (node(i, j + 1) - node(i + 1, j + 1)) +
         (1 - b) * (node(i + 1, j) - node(i + 1, j + 1));
}

cv::Vec3d SheetMesh::front_normal_at(double u, double v) const {
  const double du = w_mm / (nx - 1), dv = h_mm / (ny - 1);
  const double fu = std::clamp(u / du, 0.0, nx - 1.0), fv = std::clamp(v / dv, 0.0, ny - 1.0);
  const int i = std::min(static_cast<int>(fu), nx - 2), j = std::min(static_cast<int>(fv), ny - 2);
  cv::Vec3d n;
  if ((fu - i) + (fv - j) <= 1.0)
    n = (node(i + 1, j) - node(i, j)).cross(node(i, j + 1) - node(i, j));
  else
    n = (node(i, j + 1) - node(i + 1, j + 1)).cross(node(i + 1, j) - node(i + 1, j + 1));
  // u x v points into the paper; the printed face looks the other way.
  return -cv::normalize(n);
}

SheetMesh flat_sheet(int nx, int ny, double w, double h, const cv::Vec3d& centre, double yaw) {
  SheetMesh m;
  m.nx = nx;
  m.ny = ny;
  m.w_mm = w;
  m.h_mm = h;
  m.nodes.reserve(static_cast<std::size_t>(nx * ny));
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = i * w / (nx - 1) - w / 2, y = -(j * h / (ny - 1) - h / 2);
      m.nodes.push_back(centre + cv::Vec3d(c * x - s * y, s * x + c * y, 0.0));
    }
  return m;
}

SheetMesh fold_sheet(const SheetMesh& flat, double v_fold, double angle) {
  SheetMesh m = flat;
  const cv::Vec3d a = flat.world_at(0, v_fold), b = flat.world_at(flat.w_mm, v_fold);
  const cv::Vec3d axis = cv::normalize(b - a);
  // Sign so that a positive angle moves the flap towards the printed face.
  const cv::Vec3d nf = flat.front_normal_at(flat.w_mm / 2, v_fold);
  const cv::Vec3d flap_dir = cv::normalize(flat.world_at(flat.w_mm / 2, flat.h_mm) - flat.world_at(flat.w_mm / 2, v_fold));
  // Rodrigues: rotating flap_dir by +small about axis must gain a component along nf.
  const double sign = axis.cross(flap_dir).dot(nf) >= 0 ? 1.0 : -1.0;
  const double th = sign * angle, c = std::cos(th), s = std::sin(th);
  for (int j = 0; j < flat.ny; ++j) {
    if (flat.node_uv(0, j).y <= v_fold + 1e-9) continue;
    for (int i = 0; i < flat.nx; ++i) {
      const cv::Vec3d p = flat.node(i, j) - a;
      const cv::Vec3d r = p * c + axis.cross(p) * s + axis * axis.dot(p) * (1 - c);
      m.nodes[static_cast<std::size_t>(j * flat.nx + i)] = a + r;
    }
  }
  return m;
}

SheetMesh mesh_of(const crease::SheetState& state) {
  SheetMesh m;
  if (state.nodes_u < 2 || state.nodes_v < 2) return m;
  m.nx = state.nodes_u;
  m.ny = state.nodes_v;
  m.w_mm = state.width_mm;
  m.h_mm = state.height_mm;
  m.timestamp_ns = state.timestamp_ns;
  m.nodes.resize(static_cast<std::size_t>(m.nx) * static_cast<std::size_t>(m.ny));
  for (std::size_t k = 0; k < m.nodes.size(); ++k)
    m.nodes[k] = {state.position_mm[k][0], state.position_mm[k][1], state.position_mm[k][2]};
  return m;
}

}  // namespace crease::vision
