"""GL-free algorithms of the papers: strips, distances, Hausdorff metric, decimation."""

import warnings

# numba tries Intel TBB first for its parallel kernels and warns when the installed TBB is too
# old, then falls back to OpenMP or its own work queue: harmless, and noise for every user
warnings.filterwarnings("ignore", message="The TBB threading layer requires TBB version")
