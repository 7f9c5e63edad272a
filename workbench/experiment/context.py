"""What an experiment receives: one context with its size, output folder, progress, GL context,
measurement defaults and the shared-data guard, so that an experiment holds only its own cases
and tables.

An experiment is a function ``run(exp: ExperimentContext) -> list[dict]`` registered with
:func:`workbench.experiment.registry.experiment`. Its rows become ``table.csv``/``table.md``;
further tables go through :meth:`ExperimentContext.table`, figures into
:meth:`ExperimentContext.file`. Sizes:

* ``"full"`` — the papers' sizes (``workbench run NAME``);
* ``"quick"`` — small sizes and few repetitions (``--quick``), every table with its rows;
* ``"tiny"`` — the smallest cases that still give every table, row kind and column, for the
  tests of an experiment's shape (seconds, not minutes). Its numbers mean nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from ..data import shared_file
from ..measurement.stats import StoppingRule
from ..measurement.timing import empty_gpu_note
from ..output.tables import table_columns, write_table

if TYPE_CHECKING:
    import moderngl

    from ..measurement.rows import Measurement
    from ..paths.backends import Backend
    from ..paths.base import RenderPath
    from ..scene.protocol import Scene
    from .declare import Declaration

T = TypeVar("T")

SIZES = ("full", "quick", "tiny")
FULL_REPEATS, QUICK_REPEATS = 9, 5
# draws go on until the wall median's 95 % interval is within ±2 % (full) or ±5 % (quick),
# up to these counts
FULL_STOP = StoppingRule(rel_half_width=0.02, min_samples=FULL_REPEATS, max_samples=41)
QUICK_STOP = StoppingRule(rel_half_width=0.05, min_samples=QUICK_REPEATS, max_samples=9)
# interleaved ratios (A B A B …): pairs until the ratio's interval is within ±2 % / ±5 %
FULL_RATIO_STOP = StoppingRule(rel_half_width=0.02, min_samples=FULL_REPEATS, max_samples=61)
QUICK_RATIO_STOP = StoppingRule(rel_half_width=0.05, min_samples=QUICK_REPEATS, max_samples=11)
TINY_RATIO_STOP = StoppingRule(rel_half_width=1.0, min_samples=QUICK_REPEATS,
                               max_samples=QUICK_REPEATS)


@dataclass(frozen=True)
class Case:
    """A scene an experiment measures, under the ``label`` its rows carry in the ``scene``
    column, with an optional ``kind`` (say "paper size", "car part")."""

    label: str
    scene: Scene
    kind: str = ""


@dataclass
class ExperimentContext:
    """The context of one experiment run: ``name``, ``out_dir`` (the run's own folder, swapped
    into place whole when the run ends), ``size`` (one of :data:`SIZES`) and ``progress`` (a
    callback taking one line, or None); ``declared``, the experiment's declaration, against
    which every table is checked before it is written (None: unchecked)."""

    name: str
    out_dir: Path
    size: str = "full"
    progress: Callable[[str], None] | None = None
    declared: Declaration | None = None
    skipped: list[str] = field(default_factory=list)
    tables: list[tuple[str, list[dict[str, Any]]]] = field(default_factory=list)
    gl_renderer: str | None = None  # the renderer of the run's GL context, once made
    gl_device: str | None = None  # its EGL device's identity (EGLDevice.identity), once made
    _gl_scope: ExitStack | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.size not in SIZES:
            raise ValueError(f"experiment size must be one of {SIZES}, got {self.size!r}")
        self.out_dir = Path(self.out_dir)

    # ------------------------------------------------------------------ sizes
    @property
    def quick(self) -> bool:
        """Whether this is a small run ("quick" or "tiny")."""
        return self.size != "full"

    @property
    def tiny(self) -> bool:
        """Whether this is the smallest run ("tiny")."""
        return self.size == "tiny"

    def pick(self, full: T, quick: T, tiny: T | None = None) -> T:
        """The value for this run's size: ``full``, ``quick``, or ``tiny`` (default ``quick``)."""
        if self.size == "full":
            return full
        if self.size == "tiny" and tiny is not None:
            return tiny
        return quick

    @property
    def repeats(self) -> int:
        """Timed draws per measurement: 9 at full size, 5 (the least a median and spread need)
        otherwise."""
        return FULL_REPEATS if self.size == "full" else QUICK_REPEATS

    @property
    def stop(self) -> StoppingRule | None:
        """When timed draws stop: at full size once the median's 95 % interval is within
        ±2 % (9 to 41 draws), at quick size within ±5 % (5 to 9); at tiny size after
        :attr:`repeats`."""
        if self.size == "tiny":
            return None
        return FULL_STOP if self.size == "full" else QUICK_STOP

    def ratio_stop(self, max_samples: int | None = None) -> StoppingRule:
        """When interleaved pairs stop (:mod:`workbench.measurement.interleave`): the ratio's
        95 % interval within ±2 % (full, 9 to 61 pairs) or ±5 % (quick, 5 to 11); 5 pairs at
        tiny size. ``max_samples`` lowers the most pairs (for slow peers)."""
        rule = self.pick(FULL_RATIO_STOP, QUICK_RATIO_STOP, TINY_RATIO_STOP)
        if max_samples is not None:
            rule = replace(rule, max_samples=max(rule.min_samples,
                                                 min(rule.max_samples, max_samples)))
        return rule

    # ------------------------------------------------------------------ output
    def say(self, message: str) -> None:
        """One progress line."""
        if self.progress is not None:
            self.progress(message)

    def file(self, name: str) -> Path:
        """The path of output file ``name`` inside the run's folder."""
        return self.out_dir / name

    def table(self, rows: Sequence[dict[str, Any]], name: str, title: str,
              columns: Sequence[str] | None = None) -> None:
        """Write ``rows`` as ``<name>.csv`` and ``<name>.md`` (titled, with a note where its
        GPU times are empty on a software renderer, and the declared legend under it) into the
        run's folder, and keep them in :attr:`tables` for the results store. Refuses
        (:class:`~workbench.experiment.declare.DeclarationError`) a table or a column the
        experiment did not declare, and a declared column its rows leave out."""
        rows = self.with_device(rows)
        write_table(rows, self.out_dir, name, columns=columns, title=title,
                    notes=empty_gpu_note(rows, self.gl_renderer),
                    legend=self.legend(name, rows, columns))
        self.tables.append((name, rows))

    def legend(self, name: str, rows: Sequence[dict[str, Any]],
               columns: Sequence[str] | None = None) -> list[tuple[str, str, str]]:
        """The legend of table ``name`` written from ``rows`` (``columns``: the columns
        written, default all), after checking ``rows`` against the declaration; none for an
        undeclared experiment."""
        if self.declared is None:
            return []
        table = self.declared.check(self.name, name, rows, columns)
        return table.legend(table_columns(rows) if columns is None else columns)

    def with_device(self, rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
        """``rows`` with an ``egl_device`` column (the run's EGL device identity, e.g.
        "egl0:software" or "egl1:<uuid>") on each row drawn on the run's GL renderer, so that
        two identical GPUs are told apart; rows of other renderers are left as they are."""
        if self.gl_device is None:
            return list(rows)
        return [{**row, "egl_device": self.gl_device}
                if row.get("renderer") == self.gl_renderer and "egl_device" not in row else row
                for row in rows]

    # ------------------------------------------------------------------ data and drawing
    def shared(self, relative: Path | str, what: str) -> Path | None:
        """The shared data file ``relative``, or None after saying that ``what`` is skipped
        (and why) and recording it in ``skipped``."""
        path = shared_file(relative)
        if path is None:
            self.skipped.append(what)
            self.say(f"{what} skipped: {relative} not found (set WORKBENCH_DATA to the shared "
                     f"data folder)")
        return path

    def builtin(self, name: str, what: str | None = None) -> Scene | None:
        """The built-in scene ``name`` (at this run's size where it has one); None, said and
        recorded, where its shared data is absent."""
        from ..scene.builtin import builtin_scene

        try:
            return builtin_scene(name, quick=self.quick)
        except FileNotFoundError as exc:
            what = what or name
            self.skipped.append(what)
            self.say(f"{what} skipped: {exc}")
            return None

    @cached_property
    def gl(self) -> moderngl.Context:
        """The run's headless GL context, created on first use (and current from then on), on
        the EGL device ``WORKBENCH_EGL_DEVICE`` names (default 0; ``--device`` sets it)."""
        from ..gl.context import create_context, egl, keeping_current, renderer
        from ..gl.devices import current_device

        scope = ExitStack()
        restore = scope.enter_context(keeping_current())
        try:
            ctx = create_context()
        except BaseException:
            scope.close()
            raise
        restore.display = egl().eglGetCurrentDisplay()
        self._gl_scope = scope
        self.gl_renderer = renderer(ctx)
        device = current_device()
        self.gl_device = device.identity if device is not None else None
        return ctx

    def close(self) -> None:
        """Release the run's GL context, if one was made, with every GL object still in it,
        and make current again the context that was current before it (none if none was).
        The registry calls this when the run ends, so that one process running several
        experiments holds one context at a time."""
        ctx = self.__dict__.pop("gl", None)
        if ctx is not None:
            ctx.release()
            if self._gl_scope is not None:
                self._gl_scope.close()
                self._gl_scope = None

    @property
    def renderer(self) -> str:
        """The GL renderer rows name."""
        from ..gl import renderer

        return renderer(self.gl)

    def measure(self, scene: Scene, path: str | RenderPath, style: object | None = None, *,
                backend: moderngl.Context | Backend | None = None,
                **options: Any) -> Measurement:
        """:func:`~workbench.measurement.rows.measure` on ``backend`` (default the run's GL
        context) with this run's repeats and stopping rule unless ``repeats`` or ``stop`` is
        given."""
        from ..measurement.rows import measure

        options.setdefault("repeats", self.repeats)
        options.setdefault("stop", self.stop)
        return measure(self.gl if backend is None else backend, scene, path, style, **options)
