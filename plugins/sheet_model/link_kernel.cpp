#include "link_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define CREASE_SHEET_X86 1
#endif

namespace crease::sheet {
namespace {

constexpr int kVec = 8;            // AVX2 lanes of float
constexpr int kVec16 = 16;         // AVX-512 lanes of float; batches are padded to this
constexpr float kMinLen2 = 1e-18f; // mm^2: coincident ends are left alone

struct Arrays {
  float* x;
  float* y;
  float* z;
  const float* rest;
  const float* wa;
  const float* wb;
};

// A batch's arrays from its lane 0 on, and its loop bounds, held in locals by the vector
// paths: their stores may alias anything, so fields read through references would be loaded
// again after every store.
struct BatchView {
  int step, lanes, d;
  float *x, *y, *z;
  const float *rest, *wa, *wb;
  BatchView(const LinkKernel::Batch& bt, const Arrays& r) noexcept
      : step(bt.step), lanes(bt.lanes), d(bt.d), x(r.x + bt.a0), y(r.y + bt.a0), z(r.z + bt.a0),
        rest(r.rest + bt.data), wa(r.wa + bt.data), wb(r.wb + bt.data) {}
};

// x_a += w_a (|d| - l) / (w_a + w_b + alpha/dt_s^2) d/|d|; x_b likewise with -.
void project_lane(const LinkKernel::Batch& bt, const Arrays& r, int l) noexcept {
  const int q = bt.data + l;
  const float wa = r.wa[q], wb = r.wb[q];
  if (wa == 0.0f && wb == 0.0f) return;
  const int pa = bt.a0 + l, pb = pa + bt.d;
  const float dx = r.x[pb] - r.x[pa], dy = r.y[pb] - r.y[pa], dz = r.z[pb] - r.z[pa];
  const float len2 = dx * dx + dy * dy + dz * dz;
  if (!(len2 > kMinLen2)) return;
  const float s = 1.0f - r.rest[q] / std::sqrt(len2);
  const float fa = wa * s, fb = wb * s;
  r.x[pa] += fa * dx;
  r.y[pa] += fa * dy;
  r.z[pa] += fa * dz;
  r.x[pb] -= fb * dx;
  r.y[pb] -= fb * dy;
  r.z[pb] -= fb * dz;
}

// Lane by lane, blocks in the same order as the vector path.
void project_batch_scalar(const LinkKernel::Batch& bt, const Arrays& r) noexcept {
  for (int first = 0; first < bt.step; ++first)
    for (int l = first * bt.width; l < bt.lanes; l += bt.width * bt.step)
      for (int e = 0; e < bt.width; ++e) project_lane(bt, r, l + e);
}

// dst[r * dst_stride + c] = src[c * src_stride + r] for r < rows, c < cols; nothing else of
// dst is written (transpose_avx512 likewise, 16 at a time).
void transpose_scalar(const float* src, int src_stride, float* dst, int dst_stride, int rows, int cols) noexcept {
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      dst[static_cast<std::ptrdiff_t>(r) * dst_stride + c] = src[static_cast<std::ptrdiff_t>(c) * src_stride + r];
}

#ifdef CREASE_SHEET_X86
// 8 lanes at once (bt.width 8: bt.d >= 8). 1/|d| from rsqrt plus one Newton step (~23 bits).
__attribute__((target("avx2,fma"))) void project_batch_avx2(const LinkKernel::Batch& bt, const Arrays& r) noexcept {
  const __m256 one = _mm256_set1_ps(1.0f), half = _mm256_set1_ps(0.5f), three_halves = _mm256_set1_ps(1.5f);
  const __m256 tiny = _mm256_set1_ps(kMinLen2);
  const BatchView v(bt, r);
  for (int first = 0; first < v.step; ++first) {
    for (int l = first * kVec; l < v.lanes; l += kVec * v.step) {
      float* xa = v.x + l;
      float* ya = v.y + l;
      float* za = v.z + l;
      float* xb = xa + v.d;
      float* yb = ya + v.d;
      float* zb = za + v.d;
      __m256 ax = _mm256_loadu_ps(xa), ay = _mm256_loadu_ps(ya), az = _mm256_loadu_ps(za);
      __m256 bx = _mm256_loadu_ps(xb), by = _mm256_loadu_ps(yb), bz = _mm256_loadu_ps(zb);
      const __m256 dx = _mm256_sub_ps(bx, ax), dy = _mm256_sub_ps(by, ay), dz = _mm256_sub_ps(bz, az);
      const __m256 len2 = _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
      const __m256 ok = _mm256_cmp_ps(len2, tiny, _CMP_GT_OQ);
      const __m256 l2 = _mm256_max_ps(len2, tiny);
      __m256 inv = _mm256_rsqrt_ps(l2);
      // Newton: inv *= 1.5 - 0.5 l2 inv^2
      inv = _mm256_mul_ps(inv, _mm256_fnmadd_ps(_mm256_mul_ps(half, l2), _mm256_mul_ps(inv, inv), three_halves));
      const __m256 s = _mm256_and_ps(ok, _mm256_fnmadd_ps(_mm256_loadu_ps(v.rest + l), inv, one));
      const __m256 fa = _mm256_mul_ps(_mm256_loadu_ps(v.wa + l), s);
      const __m256 fb = _mm256_mul_ps(_mm256_loadu_ps(v.wb + l), s);
      ax = _mm256_fmadd_ps(fa, dx, ax);
      ay = _mm256_fmadd_ps(fa, dy, ay);
      az = _mm256_fmadd_ps(fa, dz, az);
      bx = _mm256_fnmadd_ps(fb, dx, bx);
      by = _mm256_fnmadd_ps(fb, dy, by);
      bz = _mm256_fnmadd_ps(fb, dz, bz);
      _mm256_storeu_ps(xa, ax);
      _mm256_storeu_ps(ya, ay);
      _mm256_storeu_ps(za, az);
      _mm256_storeu_ps(xb, bx);
      _mm256_storeu_ps(yb, by);
      _mm256_storeu_ps(zb, bz);
    }
  }
}

// 16 lanes at once (bt.width 16: bt.d >= 16). 1/|d| from rsqrt14 alone (relative error
// <= 2^-14): a link settles within 0.006 % of its rest length, 4 um on the longest (60 mm)
// links, far below the model's accuracy; a Newton step would cost a tenth of the pass.
__attribute__((target("avx512f"))) void project_batch_avx512(const LinkKernel::Batch& bt, const Arrays& r) noexcept {
  const __m512 one = _mm512_set1_ps(1.0f);
  const __m512 tiny = _mm512_set1_ps(kMinLen2);
  const BatchView v(bt, r);
  for (int first = 0; first < v.step; ++first) {
    for (int l = first * kVec16; l < v.lanes; l += kVec16 * v.step) {
      float* xa = v.x + l;
      float* ya = v.y + l;
      float* za = v.z + l;
      float* xb = xa + v.d;
      float* yb = ya + v.d;
      float* zb = za + v.d;
      __m512 ax = _mm512_loadu_ps(xa), ay = _mm512_loadu_ps(ya), az = _mm512_loadu_ps(za);
      __m512 bx = _mm512_loadu_ps(xb), by = _mm512_loadu_ps(yb), bz = _mm512_loadu_ps(zb);
      const __m512 dx = _mm512_sub_ps(bx, ax), dy = _mm512_sub_ps(by, ay), dz = _mm512_sub_ps(bz, az);
      const __m512 len2 = _mm512_fmadd_ps(dz, dz, _mm512_fmadd_ps(dy, dy, _mm512_mul_ps(dx, dx)));
      const __mmask16 ok = _mm512_cmp_ps_mask(len2, tiny, _CMP_GT_OQ);
      // maskz forms: the plain ones use _mm512_undefined_ps, which GCC 12 warns about.
      const __m512 l2 = _mm512_maskz_max_ps(0xFFFF, len2, tiny);
      const __m512 inv = _mm512_maskz_rsqrt14_ps(0xFFFF, l2);
      const __m512 s = _mm512_maskz_mov_ps(ok, _mm512_fnmadd_ps(_mm512_loadu_ps(v.rest + l), inv, one));
      const __m512 fa = _mm512_mul_ps(_mm512_loadu_ps(v.wa + l), s);
      const __m512 fb = _mm512_mul_ps(_mm512_loadu_ps(v.wb + l), s);
      _mm512_storeu_ps(xa, _mm512_fmadd_ps(fa, dx, ax));
      _mm512_storeu_ps(ya, _mm512_fmadd_ps(fa, dy, ay));
      _mm512_storeu_ps(za, _mm512_fmadd_ps(fa, dz, az));
      _mm512_storeu_ps(xb, _mm512_fnmadd_ps(fb, dx, bx));
      _mm512_storeu_ps(yb, _mm512_fnmadd_ps(fb, dy, by));
      _mm512_storeu_ps(zb, _mm512_fnmadd_ps(fb, dz, bz));
    }
  }
}

// Node positions (xyz doubles, node-major) of one grid row -> the padded float arrays of a
// row-major layout (and the copies kept for the add-back), 8 nodes at a time. Slots past
// the row's last node get 0 (they are padding). stride >= w and a multiple of 8.
__attribute__((target("avx512f"))) void row_to_floats_avx512(const double* row, int w, float* const dst[6]) noexcept {
  const __m512i ix1 = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), ix2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i iy1 = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), iy2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i iz1 = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), iz2 = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  for (int i0 = 0; i0 < w; i0 += 8) {
    const int nd = 3 * std::min(8, w - i0);  // doubles in this group
    auto mask = [nd](int first) {
      const int k = std::clamp(nd - first, 0, 8);
      return static_cast<__mmask8>((1u << k) - 1u);
    };
    const double* q = row + 3 * i0;
    const __m512d v0 = _mm512_maskz_loadu_pd(mask(0), q);
    const __m512d v1 = _mm512_maskz_loadu_pd(mask(8), q + 8);
    const __m512d v2 = _mm512_maskz_loadu_pd(mask(16), q + 16);
    const __m512d vx = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, ix1, v1), ix2, v2);
    const __m512d vy = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, iy1, v1), iy2, v2);
    const __m512d vz = _mm512_permutex2var_pd(_mm512_permutex2var_pd(v0, iz1, v1), iz2, v2);
    const __m256 fx = _mm512_maskz_cvtpd_ps(0xFF, vx), fy = _mm512_maskz_cvtpd_ps(0xFF, vy);
    const __m256 fz = _mm512_maskz_cvtpd_ps(0xFF, vz);
    _mm256_storeu_ps(dst[0] + i0, fx);
    _mm256_storeu_ps(dst[1] + i0, fy);
    _mm256_storeu_ps(dst[2] + i0, fz);
    _mm256_storeu_ps(dst[3] + i0, fx);
    _mm256_storeu_ps(dst[4] + i0, fy);
    _mm256_storeu_ps(dst[5] + i0, fz);
  }
}

// row[n] += double(now[n]) - double(old[n]) for the w nodes of one row (xyz doubles).
__attribute__((target("avx512f"))) void row_add_moves_avx512(double* row, int w, const float* const src[6]) noexcept {
  // out0 = x0 y0 z0 x1 y1 z1 x2 y2, out1 = z2 x3 y3 z3 x4 y4 z4 x5, out2 = y5 z5 x6 y6 z6 x7 y7 z7
  const __m512i a0 = _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), b0 = _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7);
  const __m512i a1 = _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), b1 = _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7);
  const __m512i a2 = _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), b2 = _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15);
  for (int i0 = 0; i0 < w; i0 += 8) {
    const int nd = 3 * std::min(8, w - i0);
    auto mask = [nd](int first) {
      const int k = std::clamp(nd - first, 0, 8);
      return static_cast<__mmask8>((1u << k) - 1u);
    };
    __m512d d[3];
    for (int c = 0; c < 3; ++c)
      d[c] = _mm512_sub_pd(_mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(src[c] + i0)),
                           _mm512_maskz_cvtps_pd(0xFF, _mm256_loadu_ps(src[c + 3] + i0)));
    const __m512d dx = d[0], dy = d[1], dz = d[2];
    const __m512d o0 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(dx, a0, dy), b0, dz);
    const __m512d o1 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(dx, a1, dy), b1, dz);
    const __m512d o2 = _mm512_permutex2var_pd(_mm512_permutex2var_pd(dx, a2, dy), b2, dz);
    double* q = row + 3 * i0;
    const __mmask8 m0 = mask(0), m1 = mask(8), m2 = mask(16);
    _mm512_mask_storeu_pd(q, m0, _mm512_add_pd(_mm512_maskz_loadu_pd(m0, q), o0));
    _mm512_mask_storeu_pd(q + 8, m1, _mm512_add_pd(_mm512_maskz_loadu_pd(m1, q + 8), o1));
    _mm512_mask_storeu_pd(q + 16, m2, _mm512_add_pd(_mm512_maskz_loadu_pd(m2, q + 16), o2));
  }
}

// dst[r * dst_stride + c] = src[c * src_stride + r] for r < rows, c < cols: 16 columns of
// one destination row per gather. Slots of dst past cols are not written.
__attribute__((target("avx512f"))) void transpose_avx512(const float* src, int src_stride, float* dst,
                                                         int dst_stride, int rows, int cols) noexcept {
  const __m512i step = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                          _mm512_set1_epi32(src_stride));
  for (int r = 0; r < rows; ++r) {
    for (int c0 = 0; c0 < cols; c0 += kVec16) {
      const auto m = static_cast<__mmask16>((1u << std::min(kVec16, cols - c0)) - 1u);
      const __m512 v = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), m, step,
                                                src + static_cast<std::ptrdiff_t>(c0) * src_stride + r, 4);
      _mm512_mask_storeu_ps(dst + static_cast<std::ptrdiff_t>(r) * dst_stride + c0, m, v);
    }
  }
}

bool cpu_has_avx2_fma() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
bool cpu_has_avx512f() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f");
}
#else
void row_to_floats_avx512(const double*, int, float* const*) noexcept {}
void transpose_avx512(const float* src, int ss, float* dst, int ds, int rows, int cols) noexcept {
  transpose_scalar(src, ss, dst, ds, rows, cols);
}
void row_add_moves_avx512(double*, int, const float* const*) noexcept {}
void project_batch_avx2(const LinkKernel::Batch& bt, const Arrays& r) noexcept { project_batch_scalar(bt, r); }
void project_batch_avx512(const LinkKernel::Batch& bt, const Arrays& r) noexcept { project_batch_scalar(bt, r); }
bool cpu_has_avx2_fma() noexcept { return false; }
bool cpu_has_avx512f() noexcept { return false; }
#endif

// Block k (of width lanes) stores b-nodes [wk + d, wk + d + w - 1], which block k + d/w
// (rounded either way)
// loads as a-nodes: visited soon after, the load would wait for the partially overlapping
// store (a store-forwarding stall). Visiting blocks with a step that divides neither
// distance puts those blocks far apart in time.
int block_step(int d, int width) {
  if (width <= 1) return 1;
  const int q1 = d / width, q2 = (d + width - 1) / width;
  for (const int m : {2, 3, 5, 7, 11, 13})
    if (q1 % m != 0 && q2 % m != 0) return m;
  return 1;
}

}  // namespace

void LinkKernel::configure(const Topology& topo, int max_simd_width) {
  w_ = topo.grid.w;
  h_ = topo.grid.h;
  lay_[0] = Layout{};
  lay_[0].stride = (w_ + kVec - 1) / kVec * kVec;
  lay_[1] = Layout{};
  lay_[1].stride = (h_ + kVec - 1) / kVec * kVec;
  lay_[1].transposed = true;
  has_avx2_ = cpu_has_avx2_fma();
  has_avx512_ = has_avx2_ && max_simd_width >= kVec16 && cpu_has_avx512f();
  use_simd_ = has_avx2_;
  // Block width of a batch with offset d (the lane-by-lane path keeps the same order).
  auto width_of = [this](int d) { return has_avx512_ && d >= kVec16 ? kVec16 : d >= kVec ? kVec : 1; };
  const int m = topo.link_count();
  lane_.assign(m, 0);
  flipped_.assign(m, 0);
  // Every link gets (layout, batch, padded a-index); a batch holds one offset d and each
  // a-index at most once.
  struct Build {
    int layout, d;
    std::vector<std::uint8_t> used;  // per padded a-index
    int lo = 1 << 30, hi = -1;
  };
  std::vector<Build> builds;
  std::map<std::pair<int, int>, std::vector<int>> by_offset;  // (layout, d) -> build ids
  std::vector<int> link_build(m), link_pa(m);
  const int padded_grid = std::max(h_ * lay_[0].stride, w_ * lay_[1].stride);
  for (int k = 0; k < m; ++k) {
    const int na = topo.a[k], nb = topo.b[k];
    // (pa, d) of the link in layout L, ordered so that d > 0; flip: topo.a is the b-node.
    auto place = [&](int L, int& pa, int& d, bool& flip) {
      const Layout& lay = lay_[L];
      pa = lay.index(na % w_, na / w_);
      int pb = lay.index(nb % w_, nb / w_);
      flip = pb < pa;
      if (flip) std::swap(pa, pb);
      d = pb - pa;
    };
    int pa = 0, d = 0, L = 0;
    bool flip = false;
    place(0, pa, d, flip);
    if (width_of(d) < kVec16) {  // the transposed layout may give it wider blocks
      int pa1 = 0, d1 = 0;
      bool flip1 = false;
      place(1, pa1, d1, flip1);
      if (width_of(d1) > width_of(d)) {
        L = 1;
        pa = pa1;
        d = d1;
        flip = flip1;
      }
    }
    flipped_[k] = flip ? 1 : 0;
    std::vector<int>& layers = by_offset[{L, d}];
    int id = -1;
    for (const int c : layers)
      if (!builds[c].used[pa]) {
        id = c;
        break;
      }
    if (id < 0) {
      id = static_cast<int>(builds.size());
      builds.push_back({L, d, std::vector<std::uint8_t>(padded_grid, 0)});
      layers.push_back(id);
    }
    Build& b = builds[id];
    b.used[pa] = 1;
    b.lo = std::min(b.lo, pa);
    b.hi = std::max(b.hi, pa);
    link_build[k] = id;
    link_pa[k] = pa;
  }
  // Batches in order of first appearance (the topology lists structural links first).
  int data = 0;
  int extent[2] = {h_ * lay_[0].stride, w_ * lay_[1].stride};
  std::vector<Batch> batch_of_build;
  for (const Build& b : builds) {
    const int a0 = b.lo / kVec16 * kVec16;  // aligned: a-node blocks are whole cache lines
    const int lanes = (b.hi - a0 + kVec16) / kVec16 * kVec16;
    const int width = width_of(b.d);
    const Batch bt{a0, b.d, lanes, data, width, block_step(b.d, width)};
    lay_[b.layout].batches.push_back(bt);
    batch_of_build.push_back(bt);
    data += lanes;
    extent[b.layout] = std::max(extent[b.layout], a0 + lanes + b.d);
  }
  for (int k = 0; k < m; ++k) {
    const Batch& bt = batch_of_build[link_build[k]];
    lane_[k] = bt.data + (link_pa[k] - bt.a0);
  }
  rest_.assign(data, 0.0f);
  wa_.assign(data, 0.0f);
  wb_.assign(data, 0.0f);
  for (int L = 0; L < 2; ++L) {
    const std::size_t e = lay_[L].batches.empty() ? 0 : static_cast<std::size_t>(extent[L]);
    lay_[L].px.assign(e, 0.0f);
    lay_[L].py.assign(e, 0.0f);
    lay_[L].pz.assign(e, 0.0f);
  }
  if (lay_[0].px.empty()) {  // positions always pass through layout 0
    lay_[0].px.assign(extent[0], 0.0f);
    lay_[0].py.assign(extent[0], 0.0f);
    lay_[0].pz.assign(extent[0], 0.0f);
  }
  ox_.assign(lay_[0].px.size(), 0.0f);
  oy_.assign(lay_[0].px.size(), 0.0f);
  oz_.assign(lay_[0].px.size(), 0.0f);
}

void LinkKernel::force_scalar(bool on) noexcept { use_simd_ = has_avx2_ && !on; }

void LinkKernel::set_link(int link, double rest_mm, double wa, double wb) noexcept {
  const int q = lane_[link];
  rest_[q] = static_cast<float>(rest_mm);
  if (flipped_[link]) std::swap(wa, wb);
  wa_[q] = static_cast<float>(wa);
  wb_[q] = static_cast<float>(wb);
}

void LinkKernel::run(Layout& lay) noexcept {
  const Arrays r{lay.px.data(), lay.py.data(), lay.pz.data(), rest_.data(), wa_.data(), wb_.data()};
  for (const Batch& bt : lay.batches) {
    if (use_simd_ && bt.width == kVec16) {
      project_batch_avx512(bt, r);
    } else if (use_simd_ && bt.width == kVec) {
      project_batch_avx2(bt, r);
    } else {
      project_batch_scalar(bt, r);
    }
  }
}

void LinkKernel::project_rt(std::span<Vec3> x) noexcept {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is read as 3 packed doubles");
  if (static_cast<int>(x.size()) < w_ * h_ || w_ * h_ == 0) return;
  // Padding nodes are reset to 0 every pass so nothing can accumulate in them.
  Layout& l0 = lay_[0];
  std::fill(l0.px.begin(), l0.px.end(), 0.0f);
  std::fill(l0.py.begin(), l0.py.end(), 0.0f);
  std::fill(l0.pz.begin(), l0.pz.end(), 0.0f);
  double* xd = &x[0].x;
  if (has_avx512_) {
    for (int j = 0; j < h_; ++j) {
      const int p = l0.index(0, j);
      float* const dst[6] = {&l0.px[p], &l0.py[p], &l0.pz[p], &ox_[p], &oy_[p], &oz_[p]};
      row_to_floats_avx512(xd + 3 * static_cast<std::ptrdiff_t>(j) * w_, w_, dst);
    }
  } else {
    for (int j = 0, n = 0; j < h_; ++j) {
      for (int i = 0; i < w_; ++i, ++n) {
        const int p = l0.index(i, j);
        l0.px[p] = ox_[p] = static_cast<float>(x[n].x);
        l0.py[p] = oy_[p] = static_cast<float>(x[n].y);
        l0.pz[p] = oz_[p] = static_cast<float>(x[n].z);
      }
    }
  }
  run(l0);
  Layout& l1 = lay_[1];
  if (!l1.batches.empty()) {
    std::fill(l1.px.begin(), l1.px.end(), 0.0f);
    std::fill(l1.py.begin(), l1.py.end(), 0.0f);
    std::fill(l1.pz.begin(), l1.pz.end(), 0.0f);
    // Layout 1 row i is layout 0 column i; and back after its batches.
    const auto transpose = has_avx512_ ? transpose_avx512 : transpose_scalar;
    float* const c0[3] = {l0.px.data(), l0.py.data(), l0.pz.data()};
    float* const c1[3] = {l1.px.data(), l1.py.data(), l1.pz.data()};
    for (int c = 0; c < 3; ++c) transpose(c0[c], l0.stride, c1[c], l1.stride, w_, h_);
    run(l1);
    for (int c = 0; c < 3; ++c) transpose(c1[c], l1.stride, c0[c], l0.stride, h_, w_);
  }
  if (has_avx512_) {
    for (int j = 0; j < h_; ++j) {
      const int p = l0.index(0, j);
      const float* const src[6] = {&l0.px[p], &l0.py[p], &l0.pz[p], &ox_[p], &oy_[p], &oz_[p]};
      row_add_moves_avx512(xd + 3 * static_cast<std::ptrdiff_t>(j) * w_, w_, src);
    }
  } else {
    for (int j = 0, n = 0; j < h_; ++j) {
      for (int i = 0; i < w_; ++i, ++n) {
        const int p = l0.index(i, j);
        x[n].x += static_cast<double>(l0.px[p]) - static_cast<double>(ox_[p]);
        x[n].y += static_cast<double>(l0.py[p]) - static_cast<double>(oy_[p]);
        x[n].z += static_cast<double>(l0.pz[p]) - static_cast<double>(oz_[p]);
      }
    }
  }
}

}  // namespace crease::sheet
