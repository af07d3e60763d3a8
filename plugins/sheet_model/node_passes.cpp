#include "node_passes.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace crease::sheet {
namespace {

void predict_scalar(Vec3* x, Vec3* v, Vec3* prev, const Vec3* pin, const std::int64_t* keep, Vec3 g, double damp,
                    double dts, int n) noexcept {
  for (int i = 0; i < n; ++i) {
    prev[i] = x[i];
    if (keep[3 * i] == 0) {
      x[i] = pin[i];
      continue;
    }
    v[i] = damp * (v[i] + dts * g);
    x[i] += dts * v[i];
  }
}

// Speed limit and pinned nodes, node by node from `first` (the velocities of nodes before
// `first` are already (x - prev) / dts, pinned ones 0, and none of their components exceeds
// sqrt(max_c2): when 3 max_c2 <= vcap^2, none of them is over the speed limit).
void finish_velocities(Vec3* x, Vec3* v, const Vec3* prev, const std::int64_t* keep, double dts, double vcap,
                       int first, double max_c2, int n) noexcept {
  const double inv = 1.0 / dts;
  for (int i = first; i < n; ++i) {
    if (keep[3 * i] == 0) {
      v[i] = Vec3{};
      continue;
    }
    v[i] = inv * (x[i] - prev[i]);
  }
  const int from = 3.0 * max_c2 <= vcap * vcap ? first : 0;
  for (int i = from; i < n; ++i) {
    const double sp2 = dot(v[i], v[i]);
    if (sp2 > vcap * vcap) {  // the move of this substep is shortened too
      v[i] *= vcap / std::sqrt(sp2);
      x[i] = prev[i] + dts * v[i];
    }
  }
}

#if defined(__x86_64__)
__attribute__((target("avx2,fma"))) void predict_avx2(double* x, double* v, double* prev, const double* pin,
                                                      const std::int64_t* keep, Vec3 g, double damp, double dts,
                                                      int m) noexcept {
  // dt_s g per component: element k is component k % 3, so the pattern repeats every 3 vectors.
  const __m256d gd[3] = {_mm256_setr_pd(dts * g.x, dts * g.y, dts * g.z, dts * g.x),
                         _mm256_setr_pd(dts * g.y, dts * g.z, dts * g.x, dts * g.y),
                         _mm256_setr_pd(dts * g.z, dts * g.x, dts * g.y, dts * g.z)};
  const __m256d vd = _mm256_set1_pd(damp), vt = _mm256_set1_pd(dts);
  int k = 0, c = 0;
  for (; k + 4 <= m; k += 4, c = c == 2 ? 0 : c + 1) {
    const __m256d xp = _mm256_loadu_pd(x + k), vv = _mm256_loadu_pd(v + k);
    const __m256d free = _mm256_castsi256_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(keep + k)));
    _mm256_storeu_pd(prev + k, xp);
    const __m256d vn = _mm256_mul_pd(vd, _mm256_add_pd(vv, gd[c]));
    const __m256d xn = _mm256_fmadd_pd(vt, vn, xp);
    _mm256_storeu_pd(x + k, _mm256_blendv_pd(_mm256_loadu_pd(pin + k), xn, free));
    _mm256_storeu_pd(v + k, _mm256_blendv_pd(vv, vn, free));
  }
  const double gc[3] = {dts * g.x, dts * g.y, dts * g.z};
  for (; k < m; ++k) {
    prev[k] = x[k];
    if (keep[k] == 0) {
      x[k] = pin[k];
      continue;
    }
    v[k] = damp * (v[k] + gc[k % 3]);
    x[k] += dts * v[k];
  }
}

// Velocities of whole 4-double groups; returns the first node not fully covered and the
// largest squared component among the groups' velocities in max_c2 (a NaN velocity is never
// capped, so it need not show there).
__attribute__((target("avx2,fma"))) int velocities_avx2(const double* x, double* v, const double* prev,
                                                        const std::int64_t* keep, double dts, int m,
                                                        double& max_c2) noexcept {
  const __m256d inv = _mm256_set1_pd(1.0 / dts);
  __m256d mx = _mm256_setzero_pd();
  int k = 0;
  for (; k + 4 <= m; k += 4) {
    const __m256d free = _mm256_castsi256_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(keep + k)));
    const __m256d vn = _mm256_and_pd(_mm256_mul_pd(inv, _mm256_sub_pd(_mm256_loadu_pd(x + k), _mm256_loadu_pd(prev + k))), free);
    _mm256_storeu_pd(v + k, vn);
    mx = _mm256_max_pd(mx, _mm256_mul_pd(vn, vn));
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, mx);
  max_c2 = 0.0;
  for (const double c : lanes) max_c2 = std::max(max_c2, c);
  return k / 3;
}

bool cpu_avx2_fma() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#else
void predict_avx2(double*, double*, double*, const double*, const std::int64_t*, Vec3, double, double, int) noexcept {}
int velocities_avx2(const double*, double*, const double*, const std::int64_t*, double, int, double& max_c2) noexcept {
  max_c2 = 0.0;
  return 0;
}
bool cpu_avx2_fma() noexcept { return false; }
#endif

}  // namespace

bool node_passes_simd_available() noexcept { return cpu_avx2_fma(); }

void predict_rt(std::span<Vec3> x, std::span<Vec3> v, std::span<Vec3> prev, std::span<const Vec3> pin,
                std::span<const std::int64_t> keep, Vec3 g, double damp, double dts, bool simd) noexcept {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is read as 3 packed doubles");
  const int n = static_cast<int>(x.size());
  if (n == 0) return;
  if (simd) {
    predict_avx2(&x[0].x, &v[0].x, &prev[0].x, &pin[0].x, keep.data(), g, damp, dts, 3 * n);
  } else {
    predict_scalar(x.data(), v.data(), prev.data(), pin.data(), keep.data(), g, damp, dts, n);
  }
}

void update_velocities_rt(std::span<Vec3> x, std::span<Vec3> v, std::span<const Vec3> prev,
                          std::span<const std::int64_t> keep, double dts, double vcap, bool simd) noexcept {
  const int n = static_cast<int>(x.size());
  if (n == 0) return;
  double max_c2 = 0.0;
  const int first = simd ? velocities_avx2(&x[0].x, &v[0].x, &prev[0].x, keep.data(), dts, 3 * n, max_c2) : 0;
  finish_velocities(x.data(), v.data(), prev.data(), keep.data(), dts, vcap, first, max_c2, n);
}

}  // namespace crease::sheet
