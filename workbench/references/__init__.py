"""Other tools run beside the workbench, each wrapped to the shape of the workbench's tables.

==========================  ======================================================
``pyrender``                pyrender, the reference renderer (EGL)
``pyvista``                 pyvista / VTK, a second reference renderer (EGL)
``simplifiers``             pymeshlab, meshoptimizer, open3d and libigl decimation
``distances``               libigl, open3d, trimesh, coal and fcpw on the
                            part-distance queries
``cascading_upper_bounds``  the certified one-sided Hausdorff bracket of Sacht &
                            Jacobson (SGP 2024)
==========================  ======================================================

Each loads its tool on first use and says under which constraints it ran."""
