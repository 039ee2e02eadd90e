// The product form of the affine transfers' per-entry algebra (framework/affine_transfer.hpp,
// written for speed): on a tensor-product stencil the P2G's momenta m v_p + m C (x_I - x_p) are
// sums of per-axis terms (Momenta) and the G2P's B_p = sum_k w_k v_k (x_k - x_p)^T is summed per
// axis node (MomentSum). Reference: the same stencil given per entry (the form CPDI and the node
// coordinates use), the textbook sums. Expected: the momenta bit for bit (the per-axis terms
// add in the per-entry sum's order), B_p to round-off (the sums are regrouped: relative 1e-14 of
// the largest |B| entry). 1D-3D, 2, 3 and 4 nodes per axis (linear, bspline2 and gimp, stretched
// gimp), random offsets, weights, velocities and matrices; particles at every position of a block.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>

#include "framework/affine_transfer.hpp"

namespace {

template <int D, int M>
void check_product_form(std::mt19937& rng, double& momenta_differing, double& moment_error) {
  using AT = loam::AffineTransfer<D>;
  constexpr int NPP = loam::ipow(M, D);
  constexpr int kB = loam::kBlock;
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  loam::StencilBlock<D> st;
  st.allocate(NPP);
  st.axis_nodes = M;
  for (int d = 0; d < D; ++d)  // axis offsets in the block's layout, h = 0.1
    for (int j = 0; j < M; ++j)
      for (int p = 0; p < kB; ++p)
        st.dx[loam::StencilBlock<D>::axis_offset_index(M, d, j) + size_t(p)] =
            0.1 * (j - 0.5 * (M - 1) + 0.4 * u(rng));
  const AT transfer;  // APIC's B_p form
  for (int p = 0; p < kB; ++p) {
    typename AT::Stencil product, entry;
    product.at = st.dx.data() + p;
    product.stride = kB;
    product.m = M;
    entry.m = 0;
    for (int k = 0; k < NPP; ++k)
      for (int j = 0; j < D; ++j) entry.own[k * D + j] = st.offset(k, j, p);
    double mv[D], mC[D][D];
    for (int d = 0; d < D; ++d) {
      mv[d] = u(rng);
      for (int j = 0; j < D; ++j) mC[d][j] = 10 * u(rng);
    }
    typename AT::template Momenta<NPP> a_product, a_entry;
    AT::template momenta<NPP>(product, NPP, mv, mC, a_product);
    AT::template momenta<NPP>(entry, NPP, mv, mC, a_entry);
    REQUIRE(a_product.product);
    REQUIRE(!a_entry.product);
    for (int k = 0; k < NPP; ++k)
      for (int d = 0; d < D; ++d) {
        double textbook = mv[d];
        for (int j = 0; j < D; ++j) textbook += mC[d][j] * entry.own[k * D + j];
        momenta_differing += a_product.at(k, d) != textbook;
        momenta_differing += a_entry.at(k, d) != textbook;
      }
    typename AT::template MomentSum<NPP> s_product, s_entry;
    s_product.clear();
    s_entry.clear();
    double B_textbook[D][D] = {}, vI[NPP][D], w[NPP];
    for (int k = 0; k < NPP; ++k) {
      w[k] = pos(rng);
      for (int d = 0; d < D; ++d) vI[k][d] = u(rng);
      transfer.add_moment(s_product, st, k, p, w[k], vI[k], product);
      transfer.add_moment(s_entry, st, k, p, w[k], vI[k], entry);
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) B_textbook[d][j] += w[k] * vI[k][d] * entry.own[k * D + j];
    }
    double B_product[D][D], B_entry[D][D], largest = 0, error = 0;
    transfer.moment(s_product, product, B_product);
    transfer.moment(s_entry, entry, B_entry);
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) {
        largest = std::max(largest, std::fabs(B_textbook[d][j]));
        error = std::max({error, std::fabs(B_product[d][j] - B_textbook[d][j]),
                          std::fabs(B_entry[d][j] - B_textbook[d][j])});
      }
    moment_error = std::max(moment_error, error / largest);
  }
}

template <int D>
void check_dimension(std::mt19937& rng) {
  double differing = 0, error = 0;
  check_product_form<D, 2>(rng, differing, error);
  check_product_form<D, 3>(rng, differing, error);
  check_product_form<D, 4>(rng, differing, error);
  std::printf(
      "affine product form %dD (2, 3, 4 nodes per axis, %d particles each): momenta differing "
      "from the per-entry sum %g, B_p relative error %.2e (tolerance 1e-14)\n",
      D, loam::kBlock, differing, error);
  CHECK(differing == 0);
  CHECK(error < 1e-14);
}

}  // namespace

TEST_CASE(
    "affine transfers: the product form on tensor-product stencils equals the per-entry sums "
    "(momenta bit for bit, B_p to round-off), 1D-3D",
    "[apic][unit]") {
  std::mt19937 rng(2026);
  check_dimension<1>(rng);
  check_dimension<2>(rng);
  check_dimension<3>(rng);
}
