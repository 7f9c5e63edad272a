"""Decimation bounded by a certified one-sided Hausdorff distance (crash2000, section 3.2).

:func:`hausdorff_decimate` removes triangles by half-edge collapses (a vertex u moves onto a
neighbour v) for as long as every point of the ORIGINAL surface stays within a tolerance of the
simplified one. Vertex coordinates never change and no vertex is created: the result is a new
index array into the caller's vertex array, which the original and the simplified mesh share
(the paper's shared coordinate set).

The distance is certified rather than sampled: every original triangle keeps a small support
of current faces that provably lies within tol of it, and a collapse is undone unless every
original triangle it touches can be certified again (:mod:`.certify`, :mod:`.recertify`).
Collapses are tried in the order of a quadric error (:mod:`.heap`), under topology and shape
rules that refuse some and count them by reason (:mod:`.rules`); feature lines, boundaries and
the common boundaries of parts are kept as polylines along which vertices only slide, and
parts slide along their common boundary together (:mod:`.constraints`).

For a result with several states (the time steps of a crash), ``states=`` certifies every
collapse at each state's coordinates too, so that the one simplified topology holds its bound
over the whole animation, and ``alive=`` decimates the triangles deleted at different states
apart (:mod:`.recertify`).

Modules, from the entry point down:

* :mod:`.decimate` -- :func:`hausdorff_decimate` and its result :class:`Decimation`;
* :mod:`.states` -- how far one decimation holds at every state of a result, measured with the
  certified metric;
* :mod:`.inputs` -- input checks and normal form (parts' tolerances, duplicate faces, normals,
  quadrics);
* :mod:`.constraints` -- fixed vertices and constrained (feature/boundary) edges;
* :mod:`.collapse` -- the compiled loop of collapses, in phases;
* :mod:`.rules` -- the topology and shape rules and the reasons of a refusal;
* :mod:`.recertify` -- the re-certification of the original triangles a collapse touches;
* :mod:`.certify` -- the certificate of one triangle, the depths and the final bounds;
* :mod:`.heap` -- the priority queue and the collapse cost;
* :mod:`.topology` -- faces and neighbours around a vertex, fans, the link condition;
* :mod:`.state` -- the groups of arrays the compiled phases share.
"""

from .certify import MAX_AUTO_DEPTH as MAX_AUTO_DEPTH
from .certify import MIN_DEPTH as MIN_DEPTH
from .certify import certification_depths
from .decimate import Decimation, hausdorff_decimate
from .rules import REJECT_REASONS as REJECT_REASONS

__all__ = ["Decimation", "certification_depths", "hausdorff_decimate"]
