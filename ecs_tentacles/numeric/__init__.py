"""Whole-array numerics any layer uses: quaternions (`quaternions`; their product alone,
numpy only, in `hamilton`), keyframed tracks
and easing (`keyframes`), optional numba kernels with numpy fallbacks
(`optional_kernels`), and runs of rows read as slices (`rows`)."""
