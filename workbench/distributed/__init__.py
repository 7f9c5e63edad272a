"""Work larger than one process, on Dask distributed: the cluster, sort-last rendering, chunked
scenes.

=============  ===================================================================
``cluster``    the Dask cluster (a ``LocalCluster`` or a scheduler address), each
               worker's GL context and the per-host draw lock
``kept``       clusters kept for a block of work (an experiment's warm-up and run)
``domains``    a mesh split into sort-last domains
``chunked``    a sort-last scene on disk, one folder per domain
``bigscene``   the es2008 benchmark written sheet by sheet as a chunked scene
``sortlast``   domains drawn on the workers and composited (the one entry point)
``schedules``  the compositing schedules (tree, swap, radix-k, local) as Dask tasks
=============  ===================================================================

The per-pixel merge and the active-pixel encoding are kernels in :mod:`workbench.algo.composite`."""
