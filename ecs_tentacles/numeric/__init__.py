"""Whole-array numerics any layer uses: quaternions (`quaternions`), keyframed tracks
and easing (`keyframes`), optional numba kernels with numpy fallbacks
(`optional_kernels`), and runs of rows read as slices (`rows`)."""
