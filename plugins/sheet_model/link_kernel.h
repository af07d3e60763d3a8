// The XPBD inner loop over links (seed 001 Eqs. 2-3, lambda = 0 per substep), the hot path.
//
// Layout: node positions are copied into float structure-of-arrays over a padded grid
// (row stride S >= W, a multiple of 8), so node (i, j) sits at j*S + i. Links are grouped
// by their grid offset: all links from node p to node p + D (D > 0 in padded indices) form
// one batch of consecutive "lanes", lane p <-> link (p, p + D). Lanes without a link carry
// zero weights and change nothing. When D >= w, any w consecutive lanes touch 2w distinct
// nodes, so they are projected at once with contiguous loads and stores (no gather, no
// colouring): w = 16 with AVX-512 (D >= 16), 8 with AVX2+FMA (D >= 8), chosen by a
// runtime CPU check; the batch is swept block by block, which is one Gauss-Seidel order.
// Links whose row-major D is short (along a row, or D < 16 with AVX-512) go to a second,
// transposed layout (node (i, j) at i*S' + j, S' >= H) when their offset is wider there:
// the pass runs the row-major batches, copies the positions across, runs the transposed
// ones and copies them back. Positions go in and the moves come back 8 nodes at a time with
// AVX-512 (permutes between xyz doubles and float arrays) when the CPU has it. Links that fit neither run lane by lane, as does every batch on a CPU
// without AVX2+FMA (same order). A topology that repeats an offset/pair gets extra batches.
//
// Configure-time: configure(). RT: everything else (no allocation).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <vector>

#include "topology.h"
#include "vec3.h"

namespace crease::sheet {

class LinkKernel {
 public:
  // Builds the padded layout and batches for topo's links (allocates). max_simd_width (16,
  // 8) caps the block width below what the CPU offers (tests of the AVX2 path).
  void configure(const Topology& topo, int max_simd_width = 16);

  // Per-link data. wa, wb: w_a / (w_a + w_b + alpha / dt_s^2) for topo.a[link] and
  // topo.b[link] (likewise b); rest: l + dl_p, mm. RT.
  void set_link(int link, double rest_mm, double wa, double wb) noexcept;
  void set_rest(int link, double rest_mm) noexcept { rest_[lane_[link]] = static_cast<float>(rest_mm); }

  // Copies positions in; one Gauss-Seidel pass over every link; adds the moves back
  // (x += new - old in float, so nodes no link moved keep their exact double value). RT.
  void project_rt(std::span<Vec3> x) noexcept;

  // false: the lane-by-lane path (no AVX2+FMA on this CPU, or forced for tests).
  [[nodiscard]] bool vectorized() const noexcept { return use_simd_; }
  [[nodiscard]] int max_width() const noexcept { return use_simd_ ? (has_avx512_ ? 16 : 8) : 1; }
  void force_scalar(bool on) noexcept;
  [[nodiscard]] int batch_count() const noexcept {
    return static_cast<int>(lay_[0].batches.size() + lay_[1].batches.size());
  }
  [[nodiscard]] int lane_count() const noexcept { return static_cast<int>(rest_.size()); }

  struct Batch {
    std::int32_t a0;     // padded index of lane 0's a-node, a multiple of 16
    std::int32_t d;      // b-node = a-node + d
    std::int32_t lanes;  // a multiple of 8
    std::int32_t data;   // first lane's slot in rest_/wa_/wb_
    std::int32_t width;  // lanes per block: 16 (AVX-512, d >= 16), 8 (AVX2, d >= 8) or 1
    std::int32_t step;   // blocks are visited r, r+step, r+2 step, ... for r < step
  };

 private:
  // A float array on a 64-byte boundary (whole AVX-512 vectors load without a cache-line
  // split when the index is a multiple of 16). assign() allocates (configure time).
  class AlignedFloats {
   public:
    void assign(std::size_t n, float v) {
      p_.reset(n > 0 ? static_cast<float*>(::operator new[](n * sizeof(float), std::align_val_t{64})) : nullptr);
      n_ = n;
      std::fill_n(p_.get(), n, v);
    }
    [[nodiscard]] float* data() noexcept { return p_.get(); }
    [[nodiscard]] const float* data() const noexcept { return p_.get(); }
    [[nodiscard]] std::size_t size() const noexcept { return n_; }
    [[nodiscard]] bool empty() const noexcept { return n_ == 0; }
    float* begin() noexcept { return p_.get(); }
    float* end() noexcept { return p_.get() + n_; }
    float& operator[](std::size_t i) noexcept { return p_[i]; }
    const float& operator[](std::size_t i) const noexcept { return p_[i]; }

   private:
    struct Free {
      void operator()(float* p) const noexcept { ::operator delete[](p, std::align_val_t{64}); }
    };
    std::unique_ptr<float[], Free> p_;
    std::size_t n_ = 0;
  };
  struct Layout {
    int stride = 0;
    bool transposed = false;
    std::vector<Batch> batches;
    AlignedFloats px, py, pz;  // padded positions
    [[nodiscard]] int index(int i, int j) const noexcept { return transposed ? i * stride + j : j * stride + i; }
  };
  void run(Layout& lay) noexcept;

  int w_ = 0, h_ = 0;
  bool use_simd_ = false, has_avx2_ = false, has_avx512_ = false;
  Layout lay_[2];                       // row-major, transposed
  std::vector<std::int32_t> lane_;      // per link: its lane slot
  std::vector<std::uint8_t> flipped_;   // per link: 1 when topo.a is the lane's b-node
  AlignedFloats rest_, wa_, wb_;        // per lane slot
  AlignedFloats ox_, oy_, oz_;          // layout 0: the values copied in (for the add-back)
};

}  // namespace crease::sheet
