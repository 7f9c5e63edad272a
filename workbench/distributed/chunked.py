"""A sort-last scene on disk: what the software rasterizer draws of one mesh path, written once
per domain, so that each worker of a cluster loads only its own domain (es2008, section 1).

:func:`write_chunked` takes a prepared :class:`~workbench.paths.software.SoftwarePath` and a
partition of its triangles (:func:`workbench.distributed.domains.split_domains`) and writes a folder
(:class:`ChunkWriter` writes one domain at a time, for scenes written part by part):

* ``scene.json`` — the manifest: format version, scene name and units, path, field and colour
  scale, the shading (colour texture included) and clip planes, the scene's bounds (model units:
  the camera a whole-scene render fits), and per domain its triangle and vertex counts;
* ``domain-NNNNN/vertices.parquet`` — per vertex the float64 drawn coordinates ``x, y, z``
  (model units, deformation applied), and where the path uses them the float32 normals
  ``nx, ny, nz`` and the normalised field ``value`` (float64, computed on the whole scene, so a
  domain is coloured and lit as in the whole scene; NaN where a node has no value, so a domain
  draws the no-result rule of :mod:`~.colormap` as the whole scene does);
* ``domain-NNNNN/triangles.parquet`` — per triangle its vertices ``a, b, c`` (int32, into the
  domain's vertices), its global index ``id`` (int64: the index one process drawing the whole
  scene gives it, which breaks depth ties when frames are composited) and, for element paths,
  its normalised ``value`` (NaN: none).

Each domain's manifest entry counts its triangles drawn in the no-result colour
(``no_result``), which a legend states. Scenes written before NaN was kept hold the sentinel
:data:`~.colormap.NO_VALUE` instead: values below −1e29 are read as NaN.

Parquet (pyarrow) keeps the columns typed and compressed; :class:`ChunkedScene` reads the
manifest and :meth:`ChunkedScene.load` one domain. :meth:`DomainChunk.render` draws a domain into
a frame of the whole image, exactly as :meth:`SoftwarePath.render_triangles
<workbench.paths.software.SoftwarePath.render_triangles>` draws the same triangles, so frames
composited in domain order give the one-process image. The folder is written under a temporary
name and renamed, so an interrupted write leaves no scene; an existing scene is replaced only
with ``replace``.

Refused (ValueError): a path that is not prepared, domains that are not a partition of its
triangles, a folder whose manifest is missing, of another format or whose domain files do not
match it.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..algo.softraster import Frame, RasterOptions, Shading, render
from ..paths.colormap import NO_VALUE

if TYPE_CHECKING:
    from ..gl import Camera
    from ..paths.software import SoftwarePath

FORMAT = "workbench-chunked-scene"
VERSION = 1
MANIFEST = "scene.json"


def _domain_folder(root: Path, index: int) -> Path:
    return root / f"domain-{index:05d}"


def write_chunked(path: SoftwarePath, domains: Sequence[np.ndarray], folder: str | os.PathLike,
                  replace: bool = False) -> Path:
    """Write the triangles of the prepared software ``path`` split into ``domains`` (sorted
    int64 arrays of indices into its triangle list, each triangle in exactly one) to ``folder``
    as a chunked scene (module notes); returns the folder.

    Refused (ValueError): an unprepared path, domains that are no partition of the path's
    triangles, an existing ``folder`` without ``replace`` (or one that is not a chunked scene).
    """
    if path.mesh is None:
        raise ValueError(f"software path {path.name!r} is not prepared")
    domains = [np.asarray(d, np.int64) for d in domains]
    _check_partition(domains, path.triangles)
    with ChunkWriter(folder, replace) as writer:
        for ids in domains:
            writer.add(path, ids)
    return writer.folder


class ChunkWriter:
    """Writes a chunked scene domain by domain (a context manager: the folder appears, whole,
    when the block ends without an exception; nothing of it remains otherwise).

    :meth:`add` writes one domain: triangles of a prepared software path, their global indices
    ``ids + first_id``. Every domain must come from the same path, field, colour scale,
    shading and clip planes, so a scene too large for one process is written part by part —
    each part a mesh of its own, prepared with the whole scene's ``Style.value_range`` — where
    its parts share no node (their normals then equal the whole scene's). The scene's bounds
    are the union of the parts' bounds; its ``name`` is given, or the first part's mesh's.
    """

    def __init__(self, folder: str | os.PathLike, replace: bool = False,
                 name: str | None = None):
        folder = Path(folder)
        if folder.exists() and not replace:
            raise ValueError(f"{folder} exists: write the chunked scene to a new folder, or "
                             f"replace")
        if folder.exists() and not (folder / MANIFEST).is_file():
            raise ValueError(f"{folder} exists and is not a chunked scene: not replaced")
        folder.parent.mkdir(parents=True, exist_ok=True)
        self.folder = folder
        self.staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", dir=folder.parent))
        self.name = name
        self._inputs = None  # (path, its raster inputs) of the last add
        self.header: dict | None = None
        self.entries: list[dict] = []
        self.lo = np.full(3, np.inf)
        self.hi = np.full(3, -np.inf)

    def __enter__(self) -> ChunkWriter:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if kind is None:
            self.close()
        else:
            shutil.rmtree(self.staging, ignore_errors=True)

    def add(self, path: SoftwarePath, ids: np.ndarray | None = None, first_id: int = 0) -> None:
        """Write the triangles ``ids`` (default all) of the prepared ``path`` as the next
        domain, with global indices ``ids + first_id``."""
        if self._inputs is None or self._inputs[0] is not path:  # one path, several domains
            self._inputs = (path, path.raster_inputs())
        inputs = self._inputs[1]
        header = _header(path, inputs)
        if self.header is None:
            self.header = header
            self.name = self.name or path.mesh.name
        elif header != self.header:
            differ = sorted(k for k in header if header[k] != self.header[k])
            raise ValueError(f"domain {len(self.entries)} differs from the first in "
                             f"{', '.join(differ)}: the domains of one scene share its path, "
                             f"field, colour scale, shading and clip planes")
        ids = (np.arange(len(inputs.triangles), dtype=np.int64) if ids is None
               else np.asarray(ids, np.int64))
        self.entries.append(_write_domain(_domain_folder(self.staging, len(self.entries)),
                                          inputs, ids, first_id))
        lo, hi = path.mesh.bounds()
        self.lo, self.hi = np.minimum(self.lo, lo), np.maximum(self.hi, hi)

    def close(self) -> Path:
        """Write the manifest and move the scene into place; the folder."""
        if not self.entries:
            shutil.rmtree(self.staging, ignore_errors=True)
            raise ValueError("need at least one domain")
        manifest = {"format": FORMAT, "version": VERSION, "name": self.name, **self.header,
                    "bounds": [self.lo.tolist(), self.hi.tolist()],
                    "triangles": int(sum(e["triangles"] for e in self.entries)),
                    "domains": self.entries}
        (self.staging / MANIFEST).write_text(json.dumps(manifest, indent=1))
        os.chmod(self.staging, 0o755)
        folder = self.folder
        if folder.exists():
            old = folder.with_name(f".{folder.name}.old")
            os.replace(folder, old)
            os.replace(self.staging, folder)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(self.staging, folder)
        return folder


def _header(path: SoftwarePath, inputs) -> dict:
    """What every domain of a chunked scene shares (the manifest less bounds and domains)."""
    shading = inputs.shading
    scale = path.scale
    return {
        "units": path.mesh.units, "path": path.name,
        "field": getattr(path.style, "field", None),
        "scale": None if scale is None else {"colormap": scale.colormap,
                                             "value_range": list(scale.value_range),
                                             "bands": scale.bands},
        "shading": {"kind": shading.kind, "base_color": list(shading.base_color),
                    "missing_color": list(shading.missing_color),
                    "texels": None if shading.texels is None
                    else np.asarray(shading.texels).tolist(),
                    "linear": bool(shading.linear), "coord": list(shading.coord),
                    "alpha_test": bool(shading.alpha_test)},
        "clip_planes": np.asarray(inputs.clip_planes, np.float64).tolist(),
    }


def _check_partition(domains: list[np.ndarray], n_triangles: int) -> None:
    if not domains:
        raise ValueError("need at least one domain")
    counts = np.zeros(n_triangles, np.int64)
    for i, ids in enumerate(domains):
        if ids.ndim != 1 or (len(ids) and (ids.min() < 0 or ids.max() >= n_triangles)):
            raise ValueError(f"domain {i} must be a 1-D array of triangle indices below "
                             f"{n_triangles}")
        np.add.at(counts, ids, 1)
    if (counts != 1).any():
        raise ValueError(f"the domains must hold every triangle exactly once: "
                         f"{int((counts == 0).sum())} missing, {int((counts > 1).sum())} "
                         f"repeated")


def _write_domain(folder: Path, inputs, ids: np.ndarray, first_id: int = 0) -> dict:
    """Write one domain's vertices and triangles (global indices ``ids + first_id``); its
    manifest entry."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    ids = np.sort(ids)
    tris = inputs.triangles[ids]
    used, local = np.unique(tris, return_inverse=True)
    local = local.reshape(-1, 3).astype(np.int32)
    xyz = inputs.coordinates[used]
    columns = {"x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]}
    if inputs.normals is not None:
        n = inputs.normals[used]
        columns |= {"nx": n[:, 0], "ny": n[:, 1], "nz": n[:, 2]}
    no_result = 0
    if inputs.values is not None:
        columns["value"] = inputs.values[used]
        no_result = int((~np.isfinite(inputs.values[tris])).any(axis=1).sum())
    folder.mkdir(parents=True)
    pq.write_table(pa.table(columns), folder / "vertices.parquet")
    triangle_columns = {"a": local[:, 0], "b": local[:, 1], "c": local[:, 2],
                        "id": ids + np.int64(first_id)}
    if inputs.triangle_values is not None:
        triangle_columns["value"] = inputs.triangle_values[ids]
        no_result = int((~np.isfinite(inputs.triangle_values[ids])).sum())
    pq.write_table(pa.table(triangle_columns), folder / "triangles.parquet")
    lo = xyz.min(axis=0) if len(xyz) else np.zeros(3)
    hi = xyz.max(axis=0) if len(xyz) else np.zeros(3)
    return {"triangles": int(len(ids)), "vertices": int(len(used)),
            "bounds": [lo.tolist(), hi.tolist()], "no_result": no_result}


# --------------------------------------------------------------------------- reading
@dataclass(eq=False)
class DomainChunk:
    """One domain of a chunked scene in memory: float64 vertex ``coordinates`` (V, 3), float32
    ``normals`` (V, 3) or None, normalised ``values`` (V,) or None, ``triangles`` (K, 3) into
    the vertices, their global ``ids`` (K,) and ``triangle_values`` (K,) or None; ``shading``
    and model-space ``clip_planes`` (P, 4) are the scene's."""

    coordinates: np.ndarray
    normals: np.ndarray | None
    values: np.ndarray | None
    triangles: np.ndarray
    ids: np.ndarray
    triangle_values: np.ndarray | None
    shading: Shading
    clip_planes: np.ndarray

    @property
    def nbytes(self) -> int:
        """Bytes of the domain's arrays."""
        return sum(a.nbytes for a in (self.coordinates, self.normals, self.values,
                                      self.triangles, self.ids, self.triangle_values)
                   if a is not None)

    def render(self, camera: Camera, size: tuple[int, int],
               options: RasterOptions | None = None,
               background: tuple[int, int, int, int] = (255, 255, 255, 255)) -> Frame:
        """A frame of the whole ``size`` (W, H) image with this domain drawn, its triangles'
        global indices as the frame's triangle indices: float32 positions relative to the
        camera's origin (subtracted in float64, as the path uploads them)."""
        origin = np.asarray(camera.origin, np.float64)
        planes = self.clip_planes.copy()
        planes[:, 3] += planes[:, :3] @ origin
        frame, _ = render((self.coordinates - origin).astype(np.float32), self.triangles,
                          camera.view_matrix(), camera.projection_matrix(), size, self.shading,
                          options or RasterOptions(), ids=self.ids, normals=self.normals,
                          values=self.values, triangle_values=self.triangle_values,
                          clip_planes=planes, background=background)
        return frame


class ChunkedScene:
    """A chunked scene folder (module notes): its ``manifest``, ``bounds`` (lo, hi) and
    :meth:`load` of one domain. Refused (ValueError): a folder without a manifest of this
    format and version."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        try:
            manifest = json.loads((self.folder / MANIFEST).read_text())
        except (OSError, ValueError) as exc:
            raise ValueError(f"{self.folder}: not a chunked scene ({exc})") from None
        if manifest.get("format") != FORMAT or manifest.get("version") != VERSION:
            raise ValueError(f"{self.folder}: a chunked scene of format {FORMAT} version "
                             f"{VERSION} expected, got {manifest.get('format')} "
                             f"{manifest.get('version')}")
        self.manifest = manifest
        s = manifest["shading"]
        self.shading = Shading(kind=s["kind"], base_color=tuple(s["base_color"]),
                               missing_color=tuple(s["missing_color"]),
                               texels=None if s["texels"] is None
                               else np.asarray(s["texels"], np.uint8),
                               linear=s["linear"], coord=tuple(s["coord"]),
                               alpha_test=s["alpha_test"])
        self.clip_planes = np.asarray(manifest["clip_planes"], np.float64).reshape(-1, 4)

    def __len__(self) -> int:
        return len(self.manifest["domains"])

    @property
    def name(self) -> str:
        return self.manifest["name"]

    @property
    def triangles(self) -> int:
        return int(self.manifest["triangles"])

    @property
    def no_result(self) -> int:
        """Triangles drawn in the no-result colour, over all domains (0 for a scene written
        before the manifest counted them)."""
        return sum(int(d.get("no_result", 0)) for d in self.manifest["domains"])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) float64 corners of the whole scene (model units)."""
        lo, hi = self.manifest["bounds"]
        return np.array(lo, np.float64), np.array(hi, np.float64)

    def domain_nbytes(self, index: int) -> int:
        """Bytes domain ``index`` takes in memory once loaded (:attr:`DomainChunk.nbytes`),
        from the manifest's counts and the columns its files hold (no data read)."""
        import pyarrow.parquet as pq

        entry, folder = self.manifest["domains"][index], _domain_folder(self.folder, index)
        vertex_columns = set(pq.read_schema(folder / "vertices.parquet").names)
        triangle_columns = set(pq.read_schema(folder / "triangles.parquet").names)
        per_vertex = 24 + 12 * ("nx" in vertex_columns) + 8 * ("value" in vertex_columns)
        per_triangle = 24 + 8 + 8 * ("value" in triangle_columns)  # a, b, c and id: int64
        return entry["vertices"] * per_vertex + entry["triangles"] * per_triangle

    def load(self, index: int) -> DomainChunk:
        """Domain ``index`` read from its Parquet files; ValueError when they do not match the
        manifest."""
        import pyarrow.parquet as pq

        if not 0 <= index < len(self):
            raise ValueError(f"{self.folder}: no domain {index} (it has {len(self)})")
        folder = _domain_folder(self.folder, index)
        vertices = pq.read_table(folder / "vertices.parquet")
        triangles = pq.read_table(folder / "triangles.parquet")
        entry = self.manifest["domains"][index]
        if vertices.num_rows != entry["vertices"] or triangles.num_rows != entry["triangles"]:
            raise ValueError(f"{folder}: {vertices.num_rows} vertices and {triangles.num_rows} "
                             f"triangles, the manifest says {entry['vertices']} and "
                             f"{entry['triangles']}")

        def column(table, name, dtype):
            return table.column(name).to_numpy().astype(dtype, copy=False)

        names = set(vertices.column_names)
        coordinates = np.column_stack([column(vertices, c, np.float64) for c in "xyz"])
        normals = (np.column_stack([column(vertices, c, np.float32) for c in ("nx", "ny", "nz")])
                   if "nx" in names else None)
        values = _no_sentinel(column(vertices, "value", np.float64)) if "value" in names \
            else None
        tris = np.column_stack([column(triangles, c, np.int64) for c in "abc"])
        triangle_values = (_no_sentinel(column(triangles, "value", np.float64))
                           if "value" in triangles.column_names else None)
        return DomainChunk(coordinates, normals, values, tris, column(triangles, "id", np.int64),
                           triangle_values, self.shading, self.clip_planes)


def _no_sentinel(values: np.ndarray) -> np.ndarray:
    """``values`` with the sentinel of older scenes (below −1e29: :data:`NO_VALUE`) as NaN."""
    old = values < 0.1 * NO_VALUE
    return np.where(old, np.nan, values) if old.any() else values


def render_chunked(scene: ChunkedScene, camera: Camera, size: tuple[int, int],
                   options: RasterOptions | None = None) -> Frame:
    """The one-process image of a chunked scene: its domains loaded and drawn one at a time
    and composited in domain order (memory bounded by one domain and two frames)."""
    from ..algo.composite.merge import composite

    result = None
    for i in range(len(scene)):
        frame = scene.load(i).render(camera, size, options)
        result = frame if result is None else composite(result, frame)
    return result
