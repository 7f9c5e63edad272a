"""The field options ``workbench render`` and ``animate`` share: the shell layer of a d3plot
(``--layer``), and what is done to the field before it is drawn (``--relative-to``,
``--envelope``, ``--smooth``; :mod:`workbench.scene.fringes`), with the help text listing the
fields a d3plot offers. A d3plot file is read with the one field drawn derived
(:mod:`workbench.scene.readers.d3plot_fields`), nothing more."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..scene.readers.d3plot_fields import DEFAULT_LAYER, FIELDS, LAYERS


def reference(text: str) -> tuple[str, int | str]:
    """``--relative-to``: ``state:K`` (("state", K)) or the file of another run (("run",
    path))."""
    head, sep, tail = text.partition(":")
    if sep and head == "state":
        try:
            return "state", int(tail)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected state:K with an integer state K, got {text!r}") from None
    return "run", text


def add_field_arguments(p: argparse.ArgumentParser) -> None:
    """Add ``--layer``, ``--relative-to``, ``--envelope`` and ``--smooth`` to ``p``."""
    p.add_argument("--layer", choices=LAYERS,
                   help=f"shell layer of a d3plot's layered fields: {', '.join(LAYERS)} "
                        f"(over the layers; default {DEFAULT_LAYER}: the mid surface)")
    p.add_argument("--relative-to", type=reference, metavar="state:K|RESULT",
                   help="draw --field minus its value at state K, or minus the same field of "
                        "another run of the same model (RESULT), mapped by node or element id")
    p.add_argument("--envelope", action="store_true",
                   help="draw the maximum of --field over the states (live elements only)")
    p.add_argument("--smooth", action="store_true",
                   help="average the element field --field to the nodes of each part (smooth "
                        "fringes that never mix parts)")


def fields_epilog() -> str:
    """The help text's list of the fields of a d3plot and what is done to them."""
    width = max(map(len, FIELDS))
    lines = ["fields of a d3plot (--field NAME; layered: --layer chooses the shell layer):"]
    lines += [f"  {name:<{width}}  {what}" for name, what in FIELDS.items()]
    lines += ["a field changed before drawing, in this order, is drawn under a new name:",
              "  --relative-to state:K   NAME_minus_stateK",
              "  --relative-to RESULT    NAME_minus_run",
              "  --envelope              NAME_envelope (maximum over the states)",
              "  --smooth                NAME_smooth (node field, averaged per part)"]
    return "\n".join(lines)


def d3plot_file(spec: str) -> str | None:
    """The d3plot file ``spec`` names: a d3plot file itself, or the shared result the built-in
    scene ``d3plot`` reads (where the shared data is found); None for anything else."""
    if spec == "d3plot" and not Path(spec).is_file():
        from ..data import D3PLOT, shared_file

        path = shared_file(D3PLOT)
        return None if path is None else str(path)
    from ..scene.readers import ParseError, detect_format

    if not Path(spec).is_file():
        return None
    try:
        return spec if detect_format(spec) == "d3plot" else None
    except ParseError:
        return None


def _read(spec: str, args, all_faces: bool, mesh_only: bool):
    """The scene ``spec``: a d3plot (a file, or the built-in ``d3plot``) read with ``--field``
    derived at ``--layer``, anything else as :func:`~workbench.scene.builtin.load_scene` reads
    it."""
    file = d3plot_file(spec)
    if file is not None:
        from ..scene.readers import read_d3plot

        wanted = [args.field] if args.field in FIELDS else []
        return read_d3plot(file, all_faces=all_faces, extra_fields=wanted,
                           layer=args.layer or DEFAULT_LAYER)
    if args.layer is not None:
        raise ValueError(f"--layer applies to d3plot results, not to {spec!r}")
    from ..scene.builtin import load_mesh, load_scene

    return (load_mesh if mesh_only else load_scene)(spec, all_faces=all_faces)


def load_with_fields(args, all_faces: bool = False, mesh_only: bool = False):
    """(scene, name of the field to draw): ``args.mesh`` read (a d3plot file with
    ``--field`` derived at ``--layer``, anything else as
    :func:`~workbench.scene.builtin.load_scene` reads it), with
    ``--relative-to``, ``--envelope`` and ``--smooth`` applied to ``args.field`` in that order
    (:mod:`workbench.scene.fringes`). ValueError (one line) for such an option without
    ``--field``, on a scene that is not an FE mesh, or that cannot be computed; KeyError for a
    field the scene lacks."""
    from ..scene import fringes

    changes = [name for name, given in (("--relative-to", args.relative_to),
                                        ("--envelope", args.envelope),
                                        ("--smooth", args.smooth)) if given]
    if changes and args.field is None:
        raise ValueError(f"{changes[0]} changes the field drawn: give --field NAME as well")
    scene = _read(args.mesh, args, all_faces, mesh_only)
    field = args.field
    if not changes:
        return scene, field
    if scene.kind != "mesh":
        raise ValueError(f"{changes[0]} applies to FE meshes, not to a {scene.kind} scene")
    if args.relative_to is not None:
        how, what = args.relative_to
        if how == "state":
            scene = fringes.relative_to_state(scene, field, what)
            field = f"{field}_minus_state{scene.step_index(what)}"
        else:
            other = _read(what, args, all_faces, mesh_only=True)
            scene = fringes.relative_to_run(scene, other, field, names=(args.mesh, what))
            field = f"{field}_minus_run"
    if args.envelope:
        scene, field = fringes.envelope(scene, field), f"{field}_envelope"
    if args.smooth:
        scene, field = fringes.part_averaged(scene, field), f"{field}_smooth"
    return scene, field
