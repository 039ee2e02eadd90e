#pragma once
// LOAM_FORCE_INLINE marks the small per-particle and per-stencil-entry building blocks of the
// step kernels (step_blocks.hpp, the F and volume updates, HeldFaces::moved). They are written
// once and called inside every scheme's innermost loops, where a call per stencil entry costs
// more than the arithmetic: GCC's inliner stops inlining them once the kernel around them grows
// (measured on the 2D bspline2 bench: add_velocity_gradient became a call per stencil entry,
// +11 % instructions per step). Forcing them inline keeps each fused loop one loop body.
#if defined(__GNUC__) || defined(__clang__)
#define LOAM_FORCE_INLINE [[gnu::always_inline]] inline
#else
#define LOAM_FORCE_INLINE inline
#endif
