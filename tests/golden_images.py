"""Golden images: a small reference PNG of a small scene for every render path and backend,
and the comparison the everyday tests make against it (``tests/paths/test_golden_images.py``).

* :data:`CASES` — the cases: a path of :data:`workbench.paths.PATHS`, a backend (``"gl"``: the
  headless EGL context; ``"software"``: the CPU rasterizer), a small scene of
  :data:`SCENES`, the path's options and the image size (W, H) in pixels.
* :func:`render_case` — the case's image, (H, W, 4) uint8 RGBA, drawn through the public
  :func:`workbench.paths.render` (no path is prepared by hand).
* :func:`compare` — per-pixel differences against a reference under a :class:`Threshold`.
* :func:`reference_for` — which reference file and threshold a case uses on a renderer.
* :func:`check` — compare (or, with ``pytest --update-golden``, rewrite) and fail with a
  message naming both renderers and the paths of the difference image, the actual image and
  the reference written under the test's tmp folder.

References live in ``tests/golden/<case id>.png``; ``tests/golden/renderer.json`` names the
renderers they were made on (``{"gl": <GL_RENDERER string>, "software": <software rasterizer
description>}``). A GL renderer other than the one named there (a real GPU, another Mesa)
uses ``tests/golden/<renderer slug>/<case id>.png`` where present (made on it by
``--update-golden``, which writes there, with a ``renderer.json`` of its own, when the
renderer is not the one of the main sidecar), else the main references under the looser
:data:`OTHER_RENDERER` threshold. To re-baseline the main references on a new renderer, delete
``tests/golden/renderer.json`` and run ``pytest --update-golden tests/paths/test_golden_images.py``.
The software rasterizer is the package's own deterministic CPU code: its references apply
everywhere, under :data:`SAME_RENDERER`.

Measured variation (``python tests/golden_images.py``, this 2-core machine, llvmpipe
"llvmpipe (LLVM 15.0.6, 256 bits)" and the software rasterizer with all threads and with one
thread): every case drawn 5 times in one process, once in a fresh subprocess and (software)
once on one thread gave the same pixels as its first draw: largest channel difference
0 levels, share of differing pixels 0 %, for all 23 cases (16 GL, 7 software); the same in
every run of the test module since.

Thresholds (8-bit levels per channel; a pixel "differs" when any channel differs by more than
``tolerance``):

* :data:`SAME_RENDERER` — tolerance 0, at most 0.1 % of the pixels may differ (4 of a 64 × 64
  image, 5 of 80 × 64), none by more than 2 levels. The measured variation is 0 on both, so
  the margin is headroom for rounding in an equivalent build, not noise: 0.1 % is a
  fifteenth of one 64-pixel line (1.56 %), 2 levels far below any band or wire colour step.
  The fault-injection tests move the one band edge of the ramp by one pixel (the colormap
  coordinate + 1/32): 32 pixels (0.78 %) change, by up to 230 levels, and both checks fail;
  the same shader edit fails the panel's vertex_color, pixel_color, element_color and the
  flange case too (81 to 760 pixels).
* :data:`OTHER_RENDERER` — a GL renderer without references of its own: tolerance 16 levels,
  at most 3 % of the pixels beyond it, no bound on the largest difference. Not measured here
  (no GPU on this machine); GPUs rasterize with the same GL rules but interpolate, filter and
  round differently, so pixels along triangle, band and wire edges may flip (about one row of
  edge pixels per feature) and shading may move by a few levels. It catches a wrong path
  (a missing band, a missing wire frame, a wrong colormap, inverted colours) but not a
  one-pixel edge move (the ramp shifted by a pixel, 2.3 % changed, passes): make references
  of that renderer for that (``--update-golden`` on it).
"""

from __future__ import annotations

import io
import json
import os
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from PIL import Image

GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
SIDECAR = GOLDEN_DIR / "renderer.json"


# --------------------------------------------------------------------------- thresholds
@dataclass(frozen=True)
class Threshold:
    """How far an image may be from its reference: pixels with any channel more than
    ``tolerance`` levels (0..255) off make up at most ``max_share`` (a share in [0, 1]) of the
    image, and no channel of any pixel is more than ``max_diff`` levels off (None: no bound)."""

    tolerance: int
    max_share: float
    max_diff: int | None


SAME_RENDERER = Threshold(tolerance=0, max_share=0.001, max_diff=2)
OTHER_RENDERER = Threshold(tolerance=16, max_share=0.03, max_diff=None)


@dataclass
class Comparison:
    """The differences of an image from its reference: ``changed`` (H, W) bool pixels beyond
    the tolerance, their ``share`` of the image, the largest channel difference ``max_diff``
    (levels), and ``failed``, the checks of the threshold that failed ("share", "max_diff",
    "shape"): empty when the image passes."""

    changed: np.ndarray
    share: float
    max_diff: int
    failed: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.failed


def compare(actual: np.ndarray, expected: np.ndarray, threshold: Threshold) -> Comparison:
    """``actual`` against ``expected`` ((H, W, 4) uint8 RGBA) under ``threshold``."""
    if actual.shape != expected.shape:
        return Comparison(np.ones(actual.shape[:2], bool), 1.0, 255, ["shape"])
    diff = np.abs(actual.astype(np.int16) - expected.astype(np.int16)).max(axis=-1)
    changed = diff > threshold.tolerance
    result = Comparison(changed, float(changed.mean()), int(diff.max()))
    if result.share > threshold.max_share:
        result.failed.append("share")
    if threshold.max_diff is not None and result.max_diff > threshold.max_diff:
        result.failed.append("max_diff")
    return result


def difference_image(actual: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8: the reference faded to light grey, every pixel that differs at all in
    red (brighter for a larger difference)."""
    grey = expected[..., :3].astype(np.float64).mean(axis=-1)
    out = np.repeat((170 + grey / 3).astype(np.uint8)[..., None], 3, axis=-1)
    diff = np.abs(actual.astype(np.int16) - expected.astype(np.int16)).max(axis=-1)
    hit = diff > 0
    out[hit] = 0
    out[hit, 0] = np.clip(128 + diff[hit], 0, 255)
    return out


# --------------------------------------------------------------------------- files
def read_png(path: Path) -> np.ndarray:
    """(H, W, 4) uint8 RGBA of the PNG at ``path``."""
    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA")).copy()


def write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and os.replace."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as a plain new file (mkstemp makes it 0600)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_png(path: Path, image: np.ndarray) -> None:
    """``image`` ((H, W, 3 or 4) uint8) as a PNG at ``path``, atomically."""
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG", optimize=True)
    write_atomic(path, buffer.getvalue())


def slug(renderer: str) -> str:
    """A folder name for ``renderer``: lower-case letters, digits and single dashes."""
    return re.sub(r"[^a-z0-9]+", "-", renderer.lower()).strip("-")


def sidecar(folder: Path | None = None) -> dict:
    """The renderers the references of ``folder`` (default :data:`GOLDEN_DIR`) were made on
    (empty where none is named)."""
    path = (folder or GOLDEN_DIR) / "renderer.json"
    return json.loads(path.read_text()) if path.exists() else {}


# --------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    """One golden image: ``path`` drawn on ``backend`` ("gl" or "software") over scene
    ``scene`` (a key of :data:`SCENES`) with the path's ``options`` into a ``size`` (W, H)
    image, seen from ``view`` (azimuth, elevation in degrees; None: the path's default camera,
    or the face-on camera of the ramp); ``variant`` tells cases of one path apart."""

    path: str
    backend: str
    scene: str
    options: tuple = ()
    variant: str = ""
    size: tuple[int, int] = (80, 64)
    view: tuple[float, float] | None = (20.0, 50.0)

    @property
    def id(self) -> str:
        return "-".join(filter(None, (self.path, self.backend, self.scene, self.variant)))


RAMP_CELLS = 32  # ramp: pixel columns across the unit quad in a 64-pixel face-on image
RAMP_BANDS = 2


@cache
def scene(name: str):
    """Scene ``name`` of :data:`SCENES`, built once per process (what paths derive on it is
    kept; every case draws it the same way)."""
    return SCENES[name]()


def _panel():
    """A stamped panel (24 × 16 elements, 1 hole, 2 beads; mm) crushed over 3 states:
    node field displacement, element field plastic_strain."""
    from workbench.scene.generators import crash_sequence, stamped_panel

    return crash_sequence(stamped_panel(24, 16, seed=3, holes=1, beads=2), steps=3)


def _ramp():
    """The quad [−0.5, 0.5]² at z = 0 as 4 × 4 elements with node field x (model units): seen
    face-on (:func:`case_camera`), x = −0.5..0.5 spans pixel columns 16..47 of a 64-pixel
    image, one column per 1/32 of the value range."""
    from meshes import quad_grid

    from workbench.scene.mesh import FEMesh

    nodes, quads = quad_grid(4, 4, span=((-0.5, 0.5), (-0.5, 0.5)))
    return FEMesh(nodes, quads, node_fields={"x": nodes[:, 0].copy()}, name="ramp")


def _plates():
    """tests/paths/test_flange.py's plates (mm): :func:`meshes.flange_plates`."""
    from meshes import flange_plates

    return flange_plates()


def _box():
    """The ghost2013 box: panels 1..6 of the cube [−1, 1]³ around part 7, [−0.2, 0.2]³."""
    from workbench.scene.generators import box_in_box

    return box_in_box(1.0, 0.2)


def _radial():
    """The st2005 spacetime plate with a radial pulse, 6 cells per side."""
    from workbench.scene.builtin import load_scene

    return load_scene("spacetime:radial:6")


SCENES = {"panel": _panel, "ramp": _ramp, "plates": _plates, "box": _box, "radial": _radial}

DISPLACEMENT = (("field", "displacement"), ("bands", 7), ("step", 2))
RAMP = (("field", "x"), ("bands", RAMP_BANDS))
_MESH = [("position", ()), ("flat", ()), ("gouraud", ()), ("vertex_color", DISPLACEMENT),
         ("pixel_color", DISPLACEMENT),
         ("element_color", (("field", "plastic_strain"), ("bands", 6), ("step", 2)))]
RAMP_CASES = {backend: Case("pixel_color", backend, "ramp", RAMP, size=(64, 64), view=None)
              for backend in ("gl", "software")}

CASES: tuple[Case, ...] = (
    *(Case(name, "gl", "panel", options) for name, options in _MESH),
    Case("flat", "gl", "panel", (("wireframe", True),), "wire"),
    Case("quad_wire", "gl", "panel"),
    *(Case(name, "gl", "panel") for name in ("fe_wire_texture", "fe_normal_map",
                                             "fe_normal_wire")),
    Case("flange", "gl", "plates", (("threshold", 2.0),)),
    Case("exploded", "gl", "box", (("focus", 7), ("plane", "x"), ("offset", 0.5)), view=None),
    *(Case(name, "gl", "radial", size=(64, 64), view=None)
      for name in ("spacetime_vertex", "spacetime_pixel")),
    RAMP_CASES["gl"],
    *(Case(name, "software", "panel", options) for name, options in _MESH),
    RAMP_CASES["software"],
)


def case_camera(case: Case, path):
    """The camera of ``case`` for the made ``path``: face-on for the ramp (±1 unit around the
    origin, 2/64 units per pixel), else the path's default camera from ``case.view`` (None: the
    path's default view)."""
    from workbench.gl import Camera

    if case.scene == "ramp":
        return Camera.fit(np.zeros(3), 1.0, margin=1.0)
    if case.view is None:
        return None
    return path.default_camera(scene(case.scene), case.size, view=case.view, style=path.style)


def backend_of(case: Case, ctx=None):
    """What ``case`` draws on: the moderngl ``ctx`` (gl), or a default
    :class:`~workbench.paths.SoftwareRasterizer` (software: all threads)."""
    from workbench.paths import SoftwareRasterizer

    return ctx if case.backend == "gl" else SoftwareRasterizer()


def render_case(case: Case, ctx=None, backend=None) -> np.ndarray:
    """(H, W, 4) uint8 RGBA image of ``case`` on white, row 0 at the top: drawn on ``ctx`` (a
    moderngl context; gl cases) or the software rasterizer, or on ``backend`` where given."""
    from workbench.paths import make_path, render

    path = make_path(case.path, **dict(case.options))
    return render(backend or backend_of(case, ctx), scene(case.scene), path,
                  camera=case_camera(case, path), size=case.size)


# --------------------------------------------------------------------------- references
@dataclass(frozen=True)
class Reference:
    """Where a case's reference is (``file``), the ``threshold`` it is compared under, the
    renderer it was made on (``made_on``) and whether it was made on the renderer drawing now
    (``own``)."""

    file: Path
    threshold: Threshold
    made_on: str
    own: bool


def reference_for(case: Case, renderer: str) -> Reference:
    """The reference of ``case`` for a draw on ``renderer`` (see the module docstring)."""
    main = GOLDEN_DIR / f"{case.id}.png"
    made_on = sidecar().get(case.backend, "unknown (no tests/golden/renderer.json)")
    if case.backend == "software" or made_on == renderer:
        return Reference(main, SAME_RENDERER, made_on, True)
    own = GOLDEN_DIR / slug(renderer) / f"{case.id}.png"
    if own.exists():
        return Reference(own, SAME_RENDERER, renderer, True)
    return Reference(main, OTHER_RENDERER, made_on, False)


def update(case: Case, image: np.ndarray, renderer: str) -> Path:
    """Write ``image`` as the reference of ``case`` made on ``renderer`` (atomically; a file
    whose pixels are the same is left as it is) and name the renderer in the sidecar: the main
    references when ``renderer`` is theirs (or none is named yet), else the renderer's own
    folder. Returns the reference's path."""
    named = sidecar()
    if case.backend == "software" or named.get(case.backend, renderer) == renderer:
        folder, names = GOLDEN_DIR, {**named, case.backend: renderer}
    else:
        folder, names = GOLDEN_DIR / slug(renderer), {case.backend: renderer}
    if sidecar(folder) != names:
        write_atomic(folder / "renderer.json", (json.dumps(names, indent=1) + "\n").encode())
    file = folder / f"{case.id}.png"
    if not (file.exists() and np.array_equal(read_png(file), image)):
        write_png(file, image)
    return file


def check(case: Case, image: np.ndarray, renderer: str, out_dir: Path,
          update_golden: bool = False) -> Comparison:
    """Compare ``image`` of ``case`` drawn on ``renderer`` with its reference; AssertionError
    naming the differences, both renderers and the difference image (written with the actual
    image and the reference under ``out_dir``) when it fails or the reference is missing. With
    ``update_golden`` the reference is rewritten first (:func:`update`)."""
    if update_golden:
        update(case, image, renderer)
    ref = reference_for(case, renderer)
    if not ref.file.exists():
        raise AssertionError(f"{case.id}: no reference {ref.file}; make it with "
                             f"`pytest --update-golden tests/paths/test_golden_images.py`")
    expected = read_png(ref.file)
    result = compare(image, expected, ref.threshold)
    if not result.ok:
        out_dir.mkdir(parents=True, exist_ok=True)
        actual_png, diff_png = out_dir / f"{case.id}-actual.png", out_dir / f"{case.id}-diff.png"
        write_png(actual_png, image)
        write_png(out_dir / f"{case.id}-expected.png", expected)
        if "shape" not in result.failed:
            write_png(diff_png, difference_image(image, expected))
        t = ref.threshold
        raise AssertionError(
            f"{case.id} differs from {ref.file} ({', '.join(result.failed)} failed): "
            f"{int(result.changed.sum())} of {result.changed.size} pixels "
            f"({100 * result.share:.2f} %, allowed {100 * t.max_share:.2f} %) differ by more "
            f"than {t.tolerance} levels; largest channel difference {result.max_diff} levels "
            f"(allowed {t.max_diff}); drawn on {renderer!r}, reference made on "
            f"{ref.made_on!r}; difference image: {diff_png} (actual {actual_png}); "
            f"`pytest --update-golden` rewrites the reference")
    return result


# --------------------------------------------------------------------------- measurement
def _render_all(path: str) -> None:
    """Render every case once (GL on a new context) and save them to the .npz ``path``."""
    from workbench.gl import create_context

    ctx = create_context()
    np.savez_compressed(path, **{case.id: render_case(case, ctx) for case in CASES})


def measure_variation(repeats: int = 5) -> dict[str, tuple[int, float]]:
    """Per case, the largest channel difference (levels) and the largest share of differing
    pixels between its first draw in this process and ``repeats − 1`` more draws here, a draw
    with one software thread (software cases) and a draw in a fresh subprocess."""
    from workbench.algo.softraster import RasterOptions
    from workbench.gl import create_context
    from workbench.paths import SoftwareRasterizer

    ctx = create_context()
    with tempfile.TemporaryDirectory() as tmp:
        saved = Path(tmp) / "images.npz"
        subprocess.run([sys.executable, __file__, "--dump", str(saved)], check=True)
        other = dict(np.load(saved))
    found = {}
    for case in CASES:
        first = render_case(case, ctx)
        draws = [render_case(case, ctx) for _ in range(repeats - 1)] + [other[case.id]]
        if case.backend == "software":
            one = SoftwareRasterizer(RasterOptions(threads=1))
            draws.append(render_case(case, backend=one))
        exact = Threshold(0, 0.0, 0)
        results = [compare(draw, first, exact) for draw in draws]
        found[case.id] = (max(r.max_diff for r in results), max(r.share for r in results))
    return found


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    if sys.argv[1:2] == ["--dump"]:
        _render_all(sys.argv[2])
    else:
        for name, (diff, share) in measure_variation().items():
            print(f"{name:40s} max diff {diff:3d} levels, differing {100 * share:.3f} %")
