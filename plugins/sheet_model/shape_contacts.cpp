#include "shape_contacts.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace crease::sheet {
namespace {

struct Arrays {
  const std::int32_t* node;
  const double *nx, *ny, *nz, *off;
};

void solve_one(Vec3& p, const Vec3& q, const Vec3& n, double off, double ht, double friction) noexcept {
  const double pen = off + ht - dot(n, p);
  if (pen <= 0) return;
  p += pen * n;
  Vec3 dt = p - q;
  dt -= dot(dt, n) * n;
  const double slide2 = dot(dt, dt), stick = friction * pen;
  if (slide2 <= stick * stick) {
    p -= dt;
  } else if (slide2 > 0) {
    p -= (stick / std::sqrt(slide2)) * dt;
  }
}

#if defined(__x86_64__)
// solve_one on 8 contacts of distinct nodes: positions gathered, moved, scattered back.
__attribute__((target("avx512f"))) void solve_avx512(double* x, const double* prev, const double* w,
                                                     const Arrays& a, int n, double ht, double friction) noexcept {
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
  const __m512d vht = _mm512_set1_pd(ht), vfr = _mm512_set1_pd(friction);
  for (int k = 0; k < n; k += 8) {
    const auto live = static_cast<__mmask8>(n - k >= 8 ? 0xFFu : (1u << (n - k)) - 1u);
    const __m256i id = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a.node + k));
    const __m256i i3 = _mm256_add_epi32(id, _mm256_add_epi32(id, id));
    // The comparisons are the negations of solve_one's early exits (w <= 0, pen <= 0).
    const __mmask8 free = _mm512_mask_cmp_pd_mask(live, _mm512_mask_i32gather_pd(zero, live, id, w, 8), zero,
                                                  _CMP_NLE_UQ);
    __m512d px = _mm512_mask_i32gather_pd(zero, free, i3, x, 8);
    __m512d py = _mm512_mask_i32gather_pd(zero, free, i3, x + 1, 8);
    __m512d pz = _mm512_mask_i32gather_pd(zero, free, i3, x + 2, 8);
    const __m512d nx = _mm512_loadu_pd(a.nx + k), ny = _mm512_loadu_pd(a.ny + k), nz = _mm512_loadu_pd(a.nz + k);
    const __m512d dn = _mm512_fmadd_pd(nz, pz, _mm512_fmadd_pd(ny, py, _mm512_mul_pd(nx, px)));
    const __m512d pen = _mm512_sub_pd(_mm512_add_pd(_mm512_loadu_pd(a.off + k), vht), dn);
    const __mmask8 in = _mm512_mask_cmp_pd_mask(free, pen, zero, _CMP_NLE_UQ);
    if (in == 0) continue;
    px = _mm512_fmadd_pd(pen, nx, px);
    py = _mm512_fmadd_pd(pen, ny, py);
    pz = _mm512_fmadd_pd(pen, nz, pz);
    __m512d dx = _mm512_sub_pd(px, _mm512_mask_i32gather_pd(zero, in, i3, prev, 8));
    __m512d dy = _mm512_sub_pd(py, _mm512_mask_i32gather_pd(zero, in, i3, prev + 1, 8));
    __m512d dz = _mm512_sub_pd(pz, _mm512_mask_i32gather_pd(zero, in, i3, prev + 2, 8));
    const __m512d dd = _mm512_fmadd_pd(dz, nz, _mm512_fmadd_pd(dy, ny, _mm512_mul_pd(dx, nx)));
    dx = _mm512_fnmadd_pd(dd, nx, dx);
    dy = _mm512_fnmadd_pd(dd, ny, dy);
    dz = _mm512_fnmadd_pd(dd, nz, dz);
    const __m512d slide2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
    const __m512d stick = _mm512_mul_pd(vfr, pen);
    const __mmask8 sticks = _mm512_cmp_pd_mask(slide2, _mm512_mul_pd(stick, stick), _CMP_LE_OQ);
    const __mmask8 slides = _mm512_mask_cmp_pd_mask(static_cast<__mmask8>(~sticks), slide2, zero, _CMP_GT_OQ);
    // sticks: the whole tangential move is undone; slides: stick / |move| of it.
    const __m512d f = _mm512_mask_div_pd(one, slides, stick, _mm512_maskz_sqrt_pd(slides, slide2));
    const __mmask8 fr = sticks | slides;
    px = _mm512_mask_mov_pd(px, fr, _mm512_fnmadd_pd(f, dx, px));
    py = _mm512_mask_mov_pd(py, fr, _mm512_fnmadd_pd(f, dy, py));
    pz = _mm512_mask_mov_pd(pz, fr, _mm512_fnmadd_pd(f, dz, pz));
    _mm512_mask_i32scatter_pd(x, in, i3, px, 8);
    _mm512_mask_i32scatter_pd(x + 1, in, i3, py, 8);
    _mm512_mask_i32scatter_pd(x + 2, in, i3, pz, 8);
  }
}

bool cpu_has_avx512f() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f");
}
#else
void solve_avx512(double*, const double*, const double*, const Arrays&, int, double, double) noexcept {}
bool cpu_has_avx512f() noexcept { return false; }
#endif

}  // namespace

void ShapeContacts::reserve(int capacity) {
  const std::size_t m = static_cast<std::size_t>((std::max(capacity, 0) + kGroup - 1) / kGroup + 1) * kGroup;
  node_.assign(m, 0);  // padding: node 0, never live
  nx_.assign(m, 0.0);
  ny_.assign(m, 0.0);
  nz_.assign(m, 0.0);
  off_.assign(m, 0.0);
  has_simd_ = cpu_has_avx512f();
  use_simd_ = has_simd_;
  clear();
}

void ShapeContacts::clear() noexcept {
  n_ = 0;
  last_node_ = -1;
  increasing_ = true;
}

bool ShapeContacts::push(std::int32_t node, Vec3 normal, double offset_mm) noexcept {
  if (n_ >= capacity()) return false;
  increasing_ = increasing_ && node > last_node_;
  last_node_ = node;
  node_[n_] = node;
  nx_[n_] = normal.x;
  ny_[n_] = normal.y;
  nz_[n_] = normal.z;
  off_[n_] = offset_mm;
  ++n_;
  return true;
}

void ShapeContacts::solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w,
                             double ht, double friction) const noexcept {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is read as 3 packed doubles");
  if (n_ == 0) return;
  if (use_simd_ && increasing_) {
    const Arrays a{node_.data(), nx_.data(), ny_.data(), nz_.data(), off_.data()};
    solve_avx512(&x[0].x, &prev[0].x, w.data(), a, n_, ht, friction);
    return;
  }
  for (int k = 0; k < n_; ++k) {
    const std::int32_t i = node_[k];
    if (w[i] <= 0) continue;
    solve_one(x[i], prev[i], Vec3{nx_[k], ny_[k], nz_[k]}, off_[k], ht, friction);
  }
}

}  // namespace crease::sheet
