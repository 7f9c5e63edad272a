"""Chunked scenes on disk (workbench.distributed.chunked): each domain's draw data in its own files,
drawn and composited to the one-process image; the es2008 scene written sheet by sheet equals
the whole scene written at once; writes are whole or absent; bad folders are refused."""

import json
import shutil

import numpy as np
import pytest

from workbench.distributed.bigscene import write_semicylinders_chunked
from workbench.distributed.chunked import (
    MANIFEST,
    ChunkedScene,
    ChunkWriter,
    render_chunked,
    write_chunked,
)
from workbench.distributed.domains import split_domains
from workbench.paths import Style
from workbench.paths.software import SoftwarePath
from workbench.scene.generators import semicylinders
from workbench.scene.needs import derive

SIZE = (160, 120)
FIELD_PATHS = ("pixel_color", "vertex_color")


def prepared(mesh, name: str, bands: int = 6, clip=None) -> SoftwarePath:
    style = Style(field="distance", bands=bands) if name in FIELD_PATHS else Style()
    if name == "element_color":
        style = Style(field="element", bands=bands)
    if clip is not None:
        style = Style(**{**style.__dict__, "clip_planes": clip})
    path = SoftwarePath(name, style)
    derive(mesh, path.needs, path.style)
    path.prepare(None, mesh, SoftwarePath.default_camera(mesh, SIZE, view=(20.0, 10.0), up="y"))
    path.make_target(SIZE)
    return path


@pytest.fixture(scope="module")
def mesh():
    m = semicylinders(4, 12)
    m.element_fields["element"] = np.sin(np.arange(m.n_elements, dtype=float))
    return m


def frames_equal(a, b) -> bool:
    return (np.array_equal(a.color, b.color) and np.array_equal(a.depth, b.depth)
            and np.array_equal(a.triangle, b.triangle))


@pytest.mark.parametrize("name", ["pixel_color", "vertex_color", "gouraud", "flat",
                                  "element_color", "position"])
@pytest.mark.parametrize("by,count", [("space", 3), ("part", 4), ("space", 1)])
def test_a_chunked_scene_draws_the_one_process_image(tmp_path, mesh, name, by, count):
    path = prepared(mesh, name)
    whole = path.render_triangles(np.arange(path.triangles))
    folder = write_chunked(path, split_domains(mesh, count, by=by), tmp_path / "scene")
    scene = ChunkedScene(folder)
    assert len(scene) == count and scene.triangles == path.triangles
    camera = SoftwarePath.default_camera(mesh, SIZE, view=(20.0, 10.0), up="y")
    assert np.array_equal(SoftwarePath.fit_camera(*scene.bounds(), SIZE, view=(20.0, 10.0),
                                                  up="y").view_matrix(), camera.view_matrix())
    frame = render_chunked(scene, camera, SIZE)
    assert (whole.triangle >= 0).sum() > 5000
    assert frames_equal(frame, whole)
    assert all(scene.domain_nbytes(i) == scene.load(i).nbytes for i in range(count))


def test_clip_planes_travel_with_the_scene(tmp_path, mesh):
    path = prepared(mesh, "pixel_color", clip=((1.0, 0.0, 0.0, 0.0),))
    whole = path.render_triangles(np.arange(path.triangles))
    scene = ChunkedScene(write_chunked(path, split_domains(mesh, 3), tmp_path / "scene"))
    camera = SoftwarePath.default_camera(mesh, SIZE, view=(20.0, 10.0), up="y")
    frame = render_chunked(scene, camera, SIZE)
    assert frames_equal(frame, whole)
    assert 0 < (frame.triangle >= 0).sum() < (prepared(mesh, "pixel_color").render_triangles(
        np.arange(path.triangles)).triangle >= 0).sum()


@pytest.mark.parametrize("name", ["pixel_color", "gouraud", "flat"])
def test_the_es2008_scene_written_sheet_by_sheet_equals_the_whole_scene(tmp_path, name):
    write_semicylinders_chunked(tmp_path / "parts", 4, 10, path=name, bands=6)
    mesh = semicylinders(4, 10)
    style = Style(field="distance", bands=6) if name in FIELD_PATHS else Style()
    path = SoftwarePath(name, style)
    derive(mesh, path.needs, path.style)
    path.prepare(None, mesh, SoftwarePath.default_camera(mesh, (64, 64)))
    write_chunked(path, split_domains(mesh, 4, by="part"), tmp_path / "whole")
    parts, whole = ChunkedScene(tmp_path / "parts"), ChunkedScene(tmp_path / "whole")
    assert {k: v for k, v in parts.manifest.items() if k != "name"} == \
        {k: v for k, v in whole.manifest.items() if k != "name"}
    for i in range(4):
        a, b = parts.load(i), whole.load(i)
        for column in ("coordinates", "normals", "values", "triangles", "ids",
                       "triangle_values"):
            x, y = getattr(a, column), getattr(b, column)
            assert (x is None) == (y is None)
            assert x is None or np.array_equal(x, y), (i, column)


def test_a_domain_loads_from_its_own_files_only(tmp_path, mesh):
    path = prepared(mesh, "pixel_color")
    folder = write_chunked(path, split_domains(mesh, 3), tmp_path / "scene")
    ids_before = ChunkedScene(folder).load(1).ids
    for other in (0, 2):
        shutil.rmtree(folder / f"domain-{other:05d}")
    assert np.array_equal(ChunkedScene(folder).load(1).ids, ids_before)
    with pytest.raises(FileNotFoundError):
        ChunkedScene(folder).load(0)


def test_an_interrupted_write_leaves_no_scene(tmp_path, mesh, monkeypatch):
    from workbench.distributed import chunked

    path = prepared(mesh, "pixel_color")
    real, calls = chunked._write_domain, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(chunked, "_write_domain", failing)
    with pytest.raises(KeyboardInterrupt):
        write_chunked(path, split_domains(mesh, 3), tmp_path / "scene")
    assert list(tmp_path.iterdir()) == []


def test_refusals(tmp_path, mesh):
    path = prepared(mesh, "pixel_color")
    domains = split_domains(mesh, 2)
    with pytest.raises(ValueError, match="exactly once: 1 missing"):
        write_chunked(path, [domains[0], domains[1][1:]], tmp_path / "a")
    with pytest.raises(ValueError, match="exactly once: 0 missing, 1 repeated"):
        write_chunked(path, [domains[0], np.concatenate([domains[1], domains[0][:1]])],
                      tmp_path / "a")
    folder = write_chunked(path, domains, tmp_path / "scene")
    with pytest.raises(ValueError, match="exists"):
        write_chunked(path, domains, folder)
    write_chunked(path, domains, folder, replace=True)  # a scene may replace a scene
    (tmp_path / "plain").mkdir()
    with pytest.raises(ValueError, match="not a chunked scene: not replaced"):
        write_chunked(path, domains, tmp_path / "plain", replace=True)
    with pytest.raises(ValueError, match="not a chunked scene"):
        ChunkedScene(tmp_path / "plain")
    manifest = json.loads((folder / MANIFEST).read_text())
    manifest["domains"][1]["triangles"] += 1
    (folder / MANIFEST).write_text(json.dumps(manifest))
    with pytest.raises(ValueError, match="the manifest says"):
        ChunkedScene(folder).load(1)
    with pytest.raises(ValueError, match="no domain 5"):
        ChunkedScene(folder).load(5)
    other = prepared(mesh, "pixel_color", bands=3)
    with pytest.raises(ValueError, match="differs from the first in scale, shading"):
        with ChunkWriter(tmp_path / "mixed") as writer:
            writer.add(path, domains[0])
            writer.add(other, domains[1])
    assert not any(p.name.startswith((".mixed", "mixed")) for p in tmp_path.iterdir())


# ---------------------------------------------------------------------------- command line
@pytest.mark.slow  # a command-line render through a cluster and back (8 s)
def test_render_writes_a_chunked_scene_and_draws_it_again_from_its_folder(tmp_path, capsys):
    """``render --domains D --write-chunked F`` draws the plain render's image from the new
    chunked scene; ``render F`` draws it again from the folder alone, and with a colour bar
    of the field the scene was written with."""
    from PIL import Image

    from workbench.cli import main

    view = ["--size", "200x160", "--view", "20,10", "--up", "y", "--raw"]
    common = ["render", "semicylinders:12", "--field", "distance", "--bands", "6",
              "--rasterizer", "software", *view]
    one, written, again = (tmp_path / f"{n}.png" for n in ("one", "written", "again"))
    folder = tmp_path / "scene"
    assert main([*common, "-o", str(one)]) == 0
    assert main([*common, "-o", str(written), "--domains", "4", "--workers", "2",
                 "--write-chunked", str(folder)]) == 0
    assert len(ChunkedScene(folder)) == 4 and ChunkedScene(folder).triangles == 2304
    assert main(["render", str(folder), "-o", str(again), "--workers", "2", *view]) == 0
    out = capsys.readouterr().out
    assert "2304 triangles in 4 domains of" in out and "on 2 workers" in out
    images = [np.asarray(Image.open(p)) for p in (one, written, again)]
    assert (images[0][..., :3] < 250).any(axis=-1).sum() > 5000
    assert np.array_equal(images[0], images[1]) and np.array_equal(images[0], images[2])

    bar = tmp_path / "bar.png"
    assert main(["render", str(folder), "-o", str(bar), "--workers", "2", "--size", "200x160"]) == 0
    assert np.asarray(Image.open(bar)).shape[1] > 200  # the colour bar beside the image


@pytest.mark.parametrize("flags,message", [
    (["--field", "x"], "--field does not apply to a chunked scene"),
    (["--bands", "3"], "--bands does not apply to a chunked scene"),
    (["--domains", "3"], "--domains does not apply to a chunked scene"),
    (["--projection", "perspective"], "orthographic views only"),
])
def test_render_of_a_chunked_scene_refuses_what_it_fixed(tmp_path, capsys, flags, message):
    from workbench.cli import main

    folder = write_semicylinders_chunked(tmp_path / "scene", 2, 4, bands=4)
    code = main(["render", str(folder), "-o", str(tmp_path / "x.png"), *flags])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.png").exists()


def test_write_chunked_refuses_gl_and_an_existing_folder(tmp_path, capsys):
    from workbench.cli import main

    existing = tmp_path / "old"
    existing.mkdir()
    (existing / "keep.txt").write_text("mine")
    base = ["render", "semicylinders:4", "-o", str(tmp_path / "x.png"), "--domains", "2"]
    for flags, message in ((["--write-chunked", str(tmp_path / "new")], "--rasterizer software"),
                           (["--rasterizer", "software", "--write-chunked", str(existing)],
                            "it exists")):
        code = main([*base, *flags])
        err = capsys.readouterr().err
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "new").exists() and (existing / "keep.txt").read_text() == "mine"
