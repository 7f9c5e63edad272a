"""The fe2003 model of an FE mesh as a derived item (``needs = {"fepatch"}``), built once per
mesh and parameter set and kept in the mesh's cache (:mod:`workbench.scene.needs`)."""

from __future__ import annotations

from ...scene.needs import derived_item
from . import pipeline


@derived_item("fepatch", key=lambda fepatch="A": (str(fepatch),),
              from_style=lambda style: (getattr(style, "fepatch", "A"),))
def fepatch_model(mesh, fepatch: str):
    """The fe2003 model of step 0 of ``mesh`` (``.original`` and ``.simplified`` textured
    surfaces) for the parameter string ``fepatch`` ("A", "B" or "alpha_g1,d,l_outer,l_inner";
    see :func:`workbench.algo.fepatch.pipeline.build_model`)."""
    return pipeline.build_model(mesh.elements, mesh.coordinates(0), fepatch)
