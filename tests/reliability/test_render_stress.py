"""The render reliability checks: far-offset equality, the soak and determinism pass on the
paths as they are, and each check fails when its property is broken."""

import numpy as np
import pytest

from workbench.reliability import (
    RenderStressReport,
    check_determinism,
    check_far_offset,
    check_soak,
    run_render_stress,
)
from workbench.reliability import render as render_stress


def test_render_stress_passes(capsys):
    report = run_render_stress(cycles=30)
    assert report.ok, report.failures
    checks = {row["check"] for row in report.rows}
    assert checks == {"far offset", "soak", "determinism"}
    assert sum(row["check"] == "far offset" for row in report.rows) == \
        2 * len(render_stress.CHECKED_PATHS)


def test_far_offset_check_fails_on_a_moved_image(ctx, monkeypatch):
    real = render_stress._image

    def shifted(ctx, mesh, name):  # a renderer that loses the far scene's precision
        image = real(ctx, mesh, name)
        return np.roll(image, 1, axis=1) if np.abs(mesh.nodes).max() > 1e6 else image

    monkeypatch.setattr(render_stress, "_image", shifted)
    report = RenderStressReport()
    check_far_offset(ctx, report, paths=("flat",))
    assert [row["ok"] for row in report.rows] == [True, False]
    assert "pixels differ" in report.failures[0]


def test_soak_check_fails_on_a_path_that_keeps_gl_objects(ctx, monkeypatch):
    from workbench.paths import GLPath

    real_release = GLPath.release

    def leaky_release(self):
        kept = list(self._objects[:1])
        real_release(self)
        self._objects.extend(kept)  # one object never released

    monkeypatch.setattr(GLPath, "release", leaky_release)
    report = RenderStressReport()
    check_soak(ctx, report, cycles=3)
    assert not report.ok and "3 GL objects kept" in report.failures[0]


def test_determinism_check_compares_digests(ctx, monkeypatch):
    report = RenderStressReport()
    monkeypatch.setattr(render_stress, "_image",
                        lambda ctx, mesh, name: np.zeros((2, 2, 4), np.uint8))
    check_determinism(ctx, report, processes=1)  # the child draws for real: digests differ
    assert not report.ok


def test_stress_command_runs_render_suite(capsys):
    from workbench.cli import main

    assert main(["stress", "render", "--cycles", "5"]) == 0
    out = capsys.readouterr().out
    assert "render stress" in out and out.strip().endswith("OK")
    with pytest.raises(SystemExit):
        main(["stress", "nothing"])
