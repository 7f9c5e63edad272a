"""Measuring a render path: timing, interleaving, statistics, image error, one row per measurement.

===============  ======================================================================
``rows``         :func:`~.rows.measure`: a prepared path drawn, timed and compared, one
                 :class:`~.rows.Measurement` row (also ``measure_together``)
``timing``       draws and CPU work timed the same way everywhere (warm-up, repeats,
                 median with interval)
``interleave``   ratios measured A B A B … in one process, with an interval
``stats``        confidence intervals, paired ratios and the stopping rule
``images``       image error against a reference: max / mean difference, PSNR, SSIM
``bench``        the benchmark harness: cases, timed functions, the registry of
                 ``benchmarks/`` (run and stored by ``workbench bench``)
===============  ======================================================================"""
