"""Reliability suites: the mesh readers against mutated keyword decks and damaged d3plots, the
render paths far from the origin, drawn many times and in other processes.

* :mod:`~workbench.reliability.decks` — the generated keyword decks and their seeded mutations;
* :mod:`~workbench.reliability.strict` — the independent strict decoding of a deck that every
  read is checked against (node ids, coordinates, connectivity, part ids, thickness);
* :mod:`~workbench.reliability.readers` — the reader suite (:func:`run_reader_stress`) and
  its report;
* :mod:`~workbench.reliability.d3plot` — damaged copies of the shared d3plot family, each
  read compared with the undamaged read, fields included (:func:`run_d3plot_stress`);
* :mod:`~workbench.reliability.render` — far offsets, the soak and determinism
  (:func:`run_render_stress`);
* :mod:`~workbench.reliability.numerics` — the numerical suite (:func:`run_numerics_stress`):
  the geometric kernels and colour paths on adversarial inputs
  (:mod:`~workbench.reliability.numerics_cases`, :mod:`~workbench.reliability.numerics_scenes`),
  checked (:mod:`~workbench.reliability.numerics_checks`,
  :mod:`~workbench.reliability.numerics_images`) against exact rational references
  (:mod:`~workbench.reliability.exact`, :mod:`~workbench.reliability.exact_planar`);
* :mod:`~workbench.reliability.faults` — faults injected to show that a check can fail (a
  path slowed by a known share; the old distance kernel, bounds not rounded outward, a rim
  around missing values).

``workbench stress readers|render|numerics|all`` runs them (:mod:`workbench.cli.stress`).
"""

from .d3plot import (
                    D3PLOT_KINDS,
                    FAMILY_KINDS,
                    D3plotStressReport,
                    Damage,
                    compare_read,
                    damaged_d3plot,
                    damaged_family,
                    run_d3plot_stress,
)
from .decks import (
                    BENIGN,
                    BOM,
                    HARMFUL,
                    KINDS,
                    Mutation,
                    comma_deck,
                    default_decks,
                    fixed_deck,
                    long_deck,
                    mutated_deck,
                    thickness_deck,
)
from .numerics import DEFAULT_N, NumericsReport, Tally, run_numerics_stress
from .readers import (
                    FAILING,
                    OUTCOMES,
                    TIMEOUT_S,
                    Failure,
                    StressReport,
                    mesh_problem,
                    read_outcome,
                    run_reader_stress,
                    same_mesh,
)
from .render import (
                    CHECKED_PATHS,
                    OFFSETS,
                    RSS_LIMIT_MIB,
                    RenderStressReport,
                    check_determinism,
                    check_far_offset,
                    check_soak,
                    image_digest,
                    resident_mib,
                    run_render_stress,
                    stress_scene,
)
from .strict import (
                    BeyondReference,
                    Expected,
                    Refused,
                    StrictDeck,
                    expected_mesh,
                    mesh_differences,
                    strict_decode,
)

__all__ = ["BENIGN", "BeyondReference", "BOM", "check_determinism", "check_far_offset",
           "check_soak", "CHECKED_PATHS", "comma_deck", "compare_read", "D3PLOT_KINDS",
           "DEFAULT_N", "NumericsReport", "run_numerics_stress", "Tally",
           "D3plotStressReport", "Damage", "damaged_d3plot", "damaged_family", "default_decks",
           "Expected", "expected_mesh", "FAILING", "Failure", "FAMILY_KINDS", "fixed_deck",
           "HARMFUL", "image_digest", "KINDS", "long_deck", "mesh_differences", "mesh_problem",
           "mutated_deck", "Mutation", "OFFSETS", "OUTCOMES", "read_outcome", "Refused",
           "RenderStressReport", "resident_mib", "RSS_LIMIT_MIB", "run_d3plot_stress",
           "run_reader_stress", "run_render_stress", "same_mesh", "stress_scene", "StressReport",
           "strict_decode", "StrictDeck", "thickness_deck", "TIMEOUT_S"]
