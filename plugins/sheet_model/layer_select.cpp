#include "layer_select.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace crease::sheet {

bool barycentric_inside(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n, double nn,
                        double tol, double out[3]) noexcept {
  const double inv = 1.0 / nn;
  const Vec3 pa = a - p, pb = b - p, pc = c - p;
  out[0] = dot(cross(pb, pc), n) * inv;
  out[1] = dot(cross(pc, pa), n) * inv;
  out[2] = 1.0 - out[0] - out[1];
  return out[0] >= -tol && out[1] >= -tol && out[2] >= -tol;
}

namespace {

// The test one candidate at a time, from cand[k] on.
int select_scalar(const LayerPair* cand, int k, int n, const std::int32_t* tri, const Vec3* xv, const Vec3* tri_nv,
                  double reach, double tol, double min_area2, LayerPair* out) noexcept {
  int m = 0;
  for (; k < n; ++k) {
    const LayerPair& c = cand[k];
    const Vec3& nv = tri_nv[c.tri];  // references: a Vec3 copy goes through the stack
    const double nn = dot(nv, nv);
    if (!(nn > min_area2)) continue;
    const Vec3& a = xv[tri[3 * c.tri]];
    const Vec3& p = xv[c.node];
    const double dn = dot(p - a, nv);
    if (!(dn * dn < reach * reach * nn)) continue;
    double bary[3];
    if (!barycentric_inside(p, a, xv[tri[3 * c.tri + 1]], xv[tri[3 * c.tri + 2]], nv, nn, tol, bary)) continue;
    out[m++] = {c.node, c.tri, dn >= 0 ? 1.0 : -1.0};
  }
  return m;
}

}  // namespace

#if defined(__x86_64__)
namespace {

struct V3 {
  __m512d x, y, z;
};

// Node positions (xyz doubles) of 8 node indices.
__attribute__((target("avx512f,avx2"))) inline V3 gather(const double* x, __m256i id) noexcept {
  // Masked forms: the plain ones start from an undefined vector, which GCC 12 warns about.
  const __m256i i3 = _mm256_add_epi32(id, _mm256_add_epi32(id, id));
  const __m512d z = _mm512_setzero_pd();
  return {_mm512_mask_i32gather_pd(z, 0xFF, i3, x, 8), _mm512_mask_i32gather_pd(z, 0xFF, i3, x + 1, 8),
          _mm512_mask_i32gather_pd(z, 0xFF, i3, x + 2, 8)};
}

// 8 int32 from base at the given element indices.
__attribute__((target("avx2"))) inline __m256i gather_i32(const int* base, __m256i idx) noexcept {
  return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), base, idx, _mm256_set1_epi32(-1), 4);
}

// dot(cross(u, v), n), as barycentric_inside computes it.
__attribute__((target("avx512f"))) inline __m512d triple(const V3& u, const V3& v, const V3& n) noexcept {
  const __m512d cx = _mm512_sub_pd(_mm512_mul_pd(u.y, v.z), _mm512_mul_pd(u.z, v.y));
  const __m512d cy = _mm512_sub_pd(_mm512_mul_pd(u.z, v.x), _mm512_mul_pd(u.x, v.z));
  const __m512d cz = _mm512_sub_pd(_mm512_mul_pd(u.x, v.y), _mm512_mul_pd(u.y, v.x));
  return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(cx, n.x), _mm512_mul_pd(cy, n.y)), _mm512_mul_pd(cz, n.z));
}

__attribute__((target("avx512f"))) inline V3 sub(const V3& a, const V3& b) noexcept {
  return {_mm512_sub_pd(a.x, b.x), _mm512_sub_pd(a.y, b.y), _mm512_sub_pd(a.z, b.z)};
}

__attribute__((target("avx512f,avx2"))) int layer_select_avx512(const LayerPair* cand, int n, const std::int32_t* tri,
                                                                const Vec3* xv, const Vec3* tri_nv, double reach,
                                                                double tol, double min_area2, LayerPair* out) noexcept {
  static_assert(sizeof(LayerPair) == 16 && sizeof(Vec3) == 3 * sizeof(double), "layouts read by the gathers");
  const double* x = &xv[0].x;
  const double* tn = &tri_nv[0].x;
  const auto* ci = reinterpret_cast<const int*>(cand);
  const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd();
  const __m512d vtol = _mm512_set1_pd(-tol), reach2 = _mm512_set1_pd(reach * reach);
  const __m512d area = _mm512_set1_pd(min_area2);
  const __m256i four = _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28);
  int m = 0, k = 0;
  for (; k + 8 <= n; k += 8) {
    const __m256i node = gather_i32(ci + 4 * k, four);
    const __m256i t = gather_i32(ci + 4 * k + 1, four);
    const __m256i t3 = _mm256_add_epi32(t, _mm256_add_epi32(t, t));
    const V3 nrm = gather(tn, t);
    const V3 a = gather(x, gather_i32(tri, t3));
    const V3 p = gather(x, node);
    const __m512d nn = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(nrm.x, nrm.x), _mm512_mul_pd(nrm.y, nrm.y)),
                                     _mm512_mul_pd(nrm.z, nrm.z));
    const V3 ap = sub(p, a);
    const __m512d dn = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(ap.x, nrm.x), _mm512_mul_pd(ap.y, nrm.y)),
                                     _mm512_mul_pd(ap.z, nrm.z));
    __mmask8 keep = _mm512_cmp_pd_mask(nn, area, _CMP_GT_OQ);
    keep = _mm512_mask_cmp_pd_mask(keep, _mm512_mul_pd(dn, dn), _mm512_mul_pd(reach2, nn), _CMP_LT_OQ);
    if (keep == 0) continue;
    const V3 b = gather(x, gather_i32(tri + 1, t3));
    const V3 c = gather(x, gather_i32(tri + 2, t3));
    const __m512d inv = _mm512_div_pd(one, nn);
    const V3 pa = sub(a, p), pb = sub(b, p), pc = sub(c, p);
    const __m512d o0 = _mm512_mul_pd(triple(pb, pc, nrm), inv);
    const __m512d o1 = _mm512_mul_pd(triple(pc, pa, nrm), inv);
    const __m512d o2 = _mm512_sub_pd(_mm512_sub_pd(one, o0), o1);
    keep = _mm512_mask_cmp_pd_mask(keep, o0, vtol, _CMP_GE_OQ);
    keep = _mm512_mask_cmp_pd_mask(keep, o1, vtol, _CMP_GE_OQ);
    keep = _mm512_mask_cmp_pd_mask(keep, o2, vtol, _CMP_GE_OQ);
    const __mmask8 up = _mm512_cmp_pd_mask(dn, zero, _CMP_GE_OQ);
    for (unsigned bits = keep; bits != 0; bits &= bits - 1) {
      const int e = __builtin_ctz(bits);
      out[m++] = {cand[k + e].node, cand[k + e].tri, (up >> e) & 1u ? 1.0 : -1.0};
    }
  }
  return m + select_scalar(cand, k, n, tri, xv, tri_nv, reach, tol, min_area2, out + m);  // the last few
}

}  // namespace

bool layer_select_simd_available() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx2");
}
#else
namespace {
int layer_select_avx512(const LayerPair* cand, int n, const std::int32_t* tri, const Vec3* x, const Vec3* tri_n,
                        double reach, double tol, double min_area2, LayerPair* out) noexcept {
  return select_scalar(cand, 0, n, tri, x, tri_n, reach, tol, min_area2, out);
}
}  // namespace
bool layer_select_simd_available() noexcept { return false; }
#endif

int layer_select(const LayerPair* cand, int n, const std::int32_t* tri, const Vec3* x, const Vec3* tri_n,
                 double reach, double tol, double min_area2, LayerPair* out, bool simd) noexcept {
  if (simd) return layer_select_avx512(cand, n, tri, x, tri_n, reach, tol, min_area2, out);
  return select_scalar(cand, 0, n, tri, x, tri_n, reach, tol, min_area2, out);
}

}  // namespace crease::sheet
