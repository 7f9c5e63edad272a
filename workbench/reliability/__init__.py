"""Reliability suites: the mesh readers against mutated keyword decks and damaged d3plots, the
render paths far from the origin, drawn many times and in other processes.

* :mod:`~workbench.reliability.decks` — the generated keyword decks and their seeded mutations;
* :mod:`~workbench.reliability.strict` — the independent strict count of a deck's well-formed
  cards that a read is checked against;
* :mod:`~workbench.reliability.readers` — the reader suite (:func:`run_reader_stress`) and
  its report;
* :mod:`~workbench.reliability.d3plot` — damaged copies of the shared d3plot
  (:func:`run_d3plot_stress`);
* :mod:`~workbench.reliability.render` — far offsets, the soak and determinism
  (:func:`run_render_stress`);
* :mod:`~workbench.reliability.faults` — faults injected to show that a check can fail (a
  path slowed by a known share).

``workbench stress readers|render|all`` runs them (:mod:`workbench.cli.stress`).
"""

from .d3plot import D3PLOT_KINDS, D3plotStressReport, damaged_d3plot, run_d3plot_stress
from .decks import (
                    BENIGN,
                    BOM,
                    HARMFUL,
                    KINDS,
                    Mutation,
                    comma_deck,
                    default_decks,
                    fixed_deck,
                    mutated_deck,
                    thickness_deck,
)
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
from .strict import StrictCount, strict_count

__all__ = ["BENIGN", "BOM", "CHECKED_PATHS", "D3PLOT_KINDS", "D3plotStressReport", "FAILING",
           "Failure", "HARMFUL", "KINDS", "Mutation", "OFFSETS", "OUTCOMES", "RSS_LIMIT_MIB",
           "RenderStressReport", "StressReport", "StrictCount", "TIMEOUT_S",
           "check_determinism", "check_far_offset", "check_soak", "comma_deck",
           "damaged_d3plot", "default_decks", "fixed_deck", "image_digest", "mesh_problem",
           "mutated_deck", "read_outcome", "resident_mib", "run_d3plot_stress",
           "run_reader_stress", "run_render_stress", "same_mesh", "strict_count",
           "stress_scene", "thickness_deck"]
