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

#ifdef CREASE_SHEET_X86
// 8 lanes at once (bt.width 8: bt.d >= 8). 1/|d| from rsqrt plus one Newton step (~23 bits).
__attribute__((target("avx2,fma"))) void project_batch_avx2(const LinkKernel::Batch& bt, const Arrays& r) noexcept {
  const __m256 one = _mm256_set1_ps(1.0f), half = _mm256_set1_ps(0.5f), three_halves = _mm256_set1_ps(1.5f);
  const __m256 tiny = _mm256_set1_ps(kMinLen2);
  for (int first = 0; first < bt.step; ++first) {
    for (int l = first * kVec; l < bt.lanes; l += kVec * bt.step) {
      float* xa = r.x + bt.a0 + l;
      float* ya = r.y + bt.a0 + l;
      float* za = r.z + bt.a0 + l;
      float* xb = xa + bt.d;
      float* yb = ya + bt.d;
      float* zb = za + bt.d;
      const int q = bt.data + l;
      __m256 ax = _mm256_loadu_ps(xa), ay = _mm256_loadu_ps(ya), az = _mm256_loadu_ps(za);
      __m256 bx = _mm256_loadu_ps(xb), by = _mm256_loadu_ps(yb), bz = _mm256_loadu_ps(zb);
      const __m256 dx = _mm256_sub_ps(bx, ax), dy = _mm256_sub_ps(by, ay), dz = _mm256_sub_ps(bz, az);
      const __m256 len2 = _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
      const __m256 ok = _mm256_cmp_ps(len2, tiny, _CMP_GT_OQ);
      const __m256 l2 = _mm256_max_ps(len2, tiny);
      __m256 inv = _mm256_rsqrt_ps(l2);
      // Newton: inv *= 1.5 - 0.5 l2 inv^2
      inv = _mm256_mul_ps(inv, _mm256_fnmadd_ps(_mm256_mul_ps(half, l2), _mm256_mul_ps(inv, inv), three_halves));
      const __m256 s = _mm256_and_ps(ok, _mm256_fnmadd_ps(_mm256_loadu_ps(r.rest + q), inv, one));
      const __m256 fa = _mm256_mul_ps(_mm256_loadu_ps(r.wa + q), s);
      const __m256 fb = _mm256_mul_ps(_mm256_loadu_ps(r.wb + q), s);
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

// 16 lanes at once (bt.width 16: bt.d >= 16); rsqrt14 plus one Newton step.
__attribute__((target("avx512f"))) void project_batch_avx512(const LinkKernel::Batch& bt, const Arrays& r) noexcept {
  const __m512 one = _mm512_set1_ps(1.0f), half = _mm512_set1_ps(0.5f), three_halves = _mm512_set1_ps(1.5f);
  const __m512 tiny = _mm512_set1_ps(kMinLen2);
  for (int first = 0; first < bt.step; ++first) {
    for (int l = first * kVec16; l < bt.lanes; l += kVec16 * bt.step) {
      float* xa = r.x + bt.a0 + l;
      float* ya = r.y + bt.a0 + l;
      float* za = r.z + bt.a0 + l;
      float* xb = xa + bt.d;
      float* yb = ya + bt.d;
      float* zb = za + bt.d;
      const int q = bt.data + l;
      __m512 ax = _mm512_loadu_ps(xa), ay = _mm512_loadu_ps(ya), az = _mm512_loadu_ps(za);
      __m512 bx = _mm512_loadu_ps(xb), by = _mm512_loadu_ps(yb), bz = _mm512_loadu_ps(zb);
      const __m512 dx = _mm512_sub_ps(bx, ax), dy = _mm512_sub_ps(by, ay), dz = _mm512_sub_ps(bz, az);
      const __m512 len2 = _mm512_fmadd_ps(dz, dz, _mm512_fmadd_ps(dy, dy, _mm512_mul_ps(dx, dx)));
      const __mmask16 ok = _mm512_cmp_ps_mask(len2, tiny, _CMP_GT_OQ);
      // maskz forms: the plain ones use _mm512_undefined_ps, which GCC 12 warns about.
      const __m512 l2 = _mm512_maskz_max_ps(0xFFFF, len2, tiny);
      __m512 inv = _mm512_maskz_rsqrt14_ps(0xFFFF, l2);
      inv = _mm512_mul_ps(inv, _mm512_fnmadd_ps(_mm512_mul_ps(half, l2), _mm512_mul_ps(inv, inv), three_halves));
      const __m512 s = _mm512_maskz_mov_ps(ok, _mm512_fnmadd_ps(_mm512_loadu_ps(r.rest + q), inv, one));
      const __m512 fa = _mm512_mul_ps(_mm512_loadu_ps(r.wa + q), s);
      const __m512 fb = _mm512_mul_ps(_mm512_loadu_ps(r.wb + q), s);
      _mm512_storeu_ps(xa, _mm512_fmadd_ps(fa, dx, ax));
      _mm512_storeu_ps(ya, _mm512_fmadd_ps(fa, dy, ay));
      _mm512_storeu_ps(za, _mm512_fmadd_ps(fa, dz, az));
      _mm512_storeu_ps(xb, _mm512_fnmadd_ps(fb, dx, bx));
      _mm512_storeu_ps(yb, _mm512_fnmadd_ps(fb, dy, by));
      _mm512_storeu_ps(zb, _mm512_fnmadd_ps(fb, dz, bz));
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
    const int lanes = (b.hi - b.lo + kVec16) / kVec16 * kVec16;
    const int width = width_of(b.d);
    const Batch bt{b.lo, b.d, lanes, data, width, block_step(b.d, width)};
    lay_[b.layout].batches.push_back(bt);
    batch_of_build.push_back(bt);
    data += lanes;
    extent[b.layout] = std::max(extent[b.layout], b.lo + lanes + b.d);
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
  ox_.assign(topo.grid.count(), 0.0f);
  oy_.assign(topo.grid.count(), 0.0f);
  oz_.assign(topo.grid.count(), 0.0f);
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
  // Padding nodes are reset to 0 every pass so nothing can accumulate in them.
  Layout& l0 = lay_[0];
  std::fill(l0.px.begin(), l0.px.end(), 0.0f);
  std::fill(l0.py.begin(), l0.py.end(), 0.0f);
  std::fill(l0.pz.begin(), l0.pz.end(), 0.0f);
  for (int j = 0, n = 0; j < h_; ++j) {
    for (int i = 0; i < w_; ++i, ++n) {
      const int p = l0.index(i, j);
      l0.px[p] = ox_[n] = static_cast<float>(x[n].x);
      l0.py[p] = oy_[n] = static_cast<float>(x[n].y);
      l0.pz[p] = oz_[n] = static_cast<float>(x[n].z);
    }
  }
  run(l0);
  const Layout* last = &l0;
  Layout& l1 = lay_[1];
  if (!l1.batches.empty()) {
    std::fill(l1.px.begin(), l1.px.end(), 0.0f);
    std::fill(l1.py.begin(), l1.py.end(), 0.0f);
    std::fill(l1.pz.begin(), l1.pz.end(), 0.0f);
    for (int j = 0; j < h_; ++j) {
      for (int i = 0; i < w_; ++i) {
        const int p = l0.index(i, j), q = l1.index(i, j);
        l1.px[q] = l0.px[p];
        l1.py[q] = l0.py[p];
        l1.pz[q] = l0.pz[p];
      }
    }
    run(l1);
    last = &l1;
  }
  for (int j = 0, n = 0; j < h_; ++j) {
    for (int i = 0; i < w_; ++i, ++n) {
      const int p = last->index(i, j);
      x[n].x += static_cast<double>(last->px[p]) - static_cast<double>(ox_[n]);
      x[n].y += static_cast<double>(last->py[p]) - static_cast<double>(oy_[n]);
      x[n].z += static_cast<double>(last->pz[p]) - static_cast<double>(oz_[n]);
    }
  }
}

}  // namespace crease::sheet
