"""Whole-array numerics any layer uses: quaternions (`quaternions`), keyframed tracks
and easing (`keyframes`), and optional numba kernels with numpy fallbacks
(`optional_kernels`)."""
