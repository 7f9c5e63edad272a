"""Sort-last depth compositing kernels (es2008, section 1), free of Dask and OpenGL.

=============  ==================================================================
``merge``      the per-pixel merge of domain frames and its statistics
``kernels``    the compiled merge of whole frames and of colour-only pixels
``active``     active pixels: bounding rectangle and run-length encoding (IceT)
``schedules``  the radix-k plan and the tree and binary-swap partners
=============  ==================================================================

:mod:`workbench.distributed.schedules` runs these on a cluster."""
