"""Synthetic FE scenes of the papers' kinds and sizes: pure numpy, float64, returning
:class:`FEMesh`.

- :func:`semicylinders` — the es2008 benchmark: stacked semi-cylindrical sheets with a distance
  field.
- :func:`stamped_panel`, :func:`stamped_panels` — quad-dominant stamped sheet-metal parts (beads,
  flanges, holes, a few per cent triangles) of any size, e.g. the crash2000 Table 1 model sizes.
- :func:`refine` — conforming k×k refinement of any FE shell mesh (fields and time steps follow);
  :func:`displaced` — a smooth bump along z, so that flat regions become curved.
- :func:`crash_sequence` — time steps of a smooth progressive front crush with per-node displacement
  and per-element plastic strain.
- :func:`box_in_box` — the ghost2013 test assembly: a box of six face parts hiding a smaller cube.

Lengths are millimetres unless a function says otherwise. One module per kind of scene:
:mod:`.cylinders`, :mod:`.panels` (from :mod:`.panel_plan` and :mod:`.panel_mesh`),
:mod:`.refinement`, :mod:`.crash`, :mod:`.assembly`; :mod:`.common` holds the argument checks.
"""

from .assembly import box_in_box
from .crash import crash_sequence
from .cylinders import semicylinders
from .panels import stamped_panel, stamped_panels
from .refinement import displaced, refine

__all__ = ["semicylinders", "stamped_panel", "stamped_panels", "refine", "crash_sequence",
           "box_in_box", "displaced"]
