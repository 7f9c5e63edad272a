"""``workbench penetrations``: initial penetrations of a shell model (crash2000 §4.1), every node
closer to an element of another part than half the sum of the two shell thicknesses
(:func:`workbench.algo.nearest.penetrations.penetrations`).

Prints what was checked, the penetrating nodes per pair of parts with the largest depth, and
the deepest rows; writes the whole table as CSV and/or Markdown (each written whole, a temporary
file moved into place) and a picture: the model in light grey with the thickness-aware flange
path (``threshold="thickness"``) over it, coloured by penetration depth, with a colour bar in
the model's units. The coloured layer is drawn over the grey one regardless of which is in
front, so that penetrations between sheets inside the model are seen through the outer ones.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from .arguments import add_device_argument, at_least, image_size, view_angles

LIGHTEN = 0.6  # share of white over the grey context of the picture


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``penetrations`` to the ``workbench`` command's subparsers; returns its parser."""
    p = subparsers.add_parser(
        "penetrations", help="initial penetrations with shell thickness (crash2000 §4.1)",
        description="Every node closer to an element of another part than half the sum of the "
                    "two shell thicknesses (section or element thickness; a node's thickness "
                    "in a part is the largest of that part's elements around it): depth = "
                    "(t_node + t_element)/2 - distance > 0, exact float64 distances from the "
                    "per-part element hierarchy. One row per (node, its part, other part): the "
                    "element of the largest depth.")
    p.add_argument("mesh", nargs="?", default="car",
                   help="mesh file (keyword deck, d3plot, ...) or built-in scene name "
                        "(default car)")
    p.add_argument("--self-contact", action="store_true",
                   help="also check each node against its own part, outside its neighbourhood "
                        "(the elements connected to it within reach)")
    p.add_argument("--step", type=at_least(0), default=0,
                   help="time step of the coordinates (default 0, the initial state)")
    p.add_argument("--csv", metavar="FILE", help="write every row as CSV")
    p.add_argument("--md", metavar="FILE", help="write every row as a Markdown table")
    p.add_argument("--image", metavar="FILE",
                   help="write a PNG: the model in grey, penetrations coloured by depth")
    p.add_argument("--limit", type=at_least(0), default=10, metavar="N",
                   help="deepest rows printed (default 10; the files hold all)")
    p.add_argument("--size", type=image_size, default=(800, 600), metavar="WxH",
                   help="image size (default 800x600)")
    p.add_argument("--view", type=view_angles, default=(30.0, 25.0), metavar="AZ,EL",
                   help="azimuth and elevation in degrees (default 30,25)")
    add_device_argument(p)
    p.set_defaults(func=cmd_penetrations)
    return p


def cmd_penetrations(args) -> int:
    """Check, print the summary and the deepest rows, write the files; 0 (also when nodes
    penetrate: the table is the answer)."""
    from ..algo.nearest.penetrations import penetrations
    from ..output.targets import output_target
    from ..scene.builtin import load_mesh

    for name in ("csv", "md", "image"):  # refused before the check, not after it
        if getattr(args, name):
            output_target(getattr(args, name))
    mesh = load_mesh(args.mesh)
    step = mesh.step_index(args.step, "--step")
    r = penetrations(mesh, self_contact=args.self_contact, step=step)
    for line in summary_lines(mesh, r, args.limit):
        print(line)
    columns = list(COLUMNS)
    rows = r.rows()
    if args.csv:
        print(f"  table written to {write_csv(args.csv, rows, columns)}")
    if args.md:
        print(f"  table written to {write_markdown(args.md, rows, columns, mesh, r)}")
    if args.image:
        out = write_picture(args, mesh, r, step)
        print(f"  picture written to {out}")
    return 0


COLUMNS = ("node", "part", "other_part", "element", "distance", "depth", "node_thickness",
           "element_thickness")


def summary_lines(mesh, r, limit: int) -> list[str]:
    """The printed summary: what was checked, per pair of parts the penetrating nodes and the
    largest depth, then the ``limit`` deepest rows."""
    from ..output.tables import markdown_table

    units = r.units or "model units"
    kind = "other parts and own part (self-contact)" if r.self_contact else "other parts"
    nodes = len(np.unique(r.node))
    lines = [f"{mesh.name}: {r.nodes_checked} nodes checked ({r.pairs_checked} node/part pairs) "
             f"against {kind} in {r.seconds:.3g} s; {nodes} penetrating nodes, "
             + (f"largest depth {float(r.depth.max()):.4g} {units}" if len(r) else "none")]
    if len(r.unchecked_nodes) or len(r.unknown_elements):
        lines.append(f"  not checked: {len(r.unchecked_nodes)} nodes without a known thickness; "
                     f"not measured against: {len(r.unknown_elements)} elements without one")
    if len(r):
        pairs = [dict(part=p["part"], other_part=p["other_part"], nodes=p["nodes"],
                      **{f"max_depth [{units}]": p["max_depth"]}) for p in r.pairs()]
        lines += ["", "penetrating nodes per pair of parts (node's part, other part):", "",
                  markdown_table(pairs).rstrip("\n")]
        if limit:
            shown = r.rows(limit)
            lines += ["", f"the {len(shown)} deepest of {len(r)} rows (lengths in {units}):", "",
                      markdown_table(shown).rstrip("\n")]
    return lines


def write_csv(target, rows: list[dict], columns: list[str]):
    """The rows as CSV (the header even without rows, floats at full precision), written
    whole; the path."""
    import csv

    from ..output.tables import atomic_open
    from ..output.targets import output_target

    path = output_target(target)
    with atomic_open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in rows:
            writer.writerow([row[c] for c in columns])
    return path


def write_markdown(target, rows: list[dict], columns: list[str], mesh, r):
    """The rows as a Markdown table with a title, what they are and a legend of the columns,
    written whole; the path."""
    from ..output.tables import atomic_write_text, markdown_table

    units = r.units or "model units"
    note = (f"depth = (node_thickness + element_thickness)/2 - distance > 0; {r.nodes_checked} "
            f"nodes checked against the other parts"
            f"{' and their own (self-contact)' if r.self_contact else ''}; one row per (node, "
            f"its part, other part), the element of the largest depth")
    legend = [("node", "", "node id"), ("part", "", "the node's part it was checked with"),
              ("other_part", "", "the part of the element reached"),
              ("element", "", "element id of the largest depth"),
              ("distance", units, "node to element"), ("depth", units, "penetration depth"),
              ("node_thickness", units, "the largest thickness of the part's elements at "
                                        "the node"),
              ("element_thickness", units, "thickness of the element reached")]
    text = markdown_table(rows, columns, title=f"Initial penetrations of {mesh.name}",
                          notes=[note] + ([] if rows else ["no penetrating node"]),
                          legend=legend)
    return atomic_write_text(target, text)


def write_picture(args, mesh, r, step: int):
    """The model in light grey, the penetrations over it coloured by depth (flange path,
    ``threshold="thickness"``), with a colour bar from 0 to the largest depth."""
    import matplotlib

    from ..gl import create_context
    from ..measurement.images import coverage
    from ..measurement.rows import default_camera, measure
    from ..output.figures import save_field_figure
    from ..paths.flange import FlangeStyle

    top = float(r.depth.max()) if len(r) else 1.0
    top = _round_up(top)
    style = FlangeStyle(threshold="thickness", depth_range=top, step=step)
    ctx = create_context(device=args.device)
    camera = default_camera(mesh, args.size, view=args.view)
    context = measure(ctx, mesh, "gouraud", camera=camera, size=args.size, step=step,
                      timed=False).image
    shown = measure(ctx, mesh, "flange", style, camera=camera, size=args.size, step=step,
                    timed=False).image
    image = np.round(context * (1 - LIGHTEN) + 255 * LIGHTEN).astype(np.uint8)
    drawn = coverage(shown)
    image[drawn] = shown[drawn]
    # the bar: the visible (upper) half of the path's colour scale, depth 0 .. top
    table = matplotlib.colormaps[style.colormap](np.linspace(0.5, 1.0, 128))
    n = len(np.unique(r.node))
    title = (f"{mesh.name}: {n} penetrating nodes"
             + (f", largest depth {float(r.depth.max()):.3g} {r.units}" if len(r) else ""))
    return save_field_figure(args.image, image, value_range=(0.0, top), colormap=table,
                             label="penetration depth", units=r.units, title=title)


def _round_up(value: float) -> float:
    """``value`` rounded up to 1, 2 or 5 times a power of ten (a colour bar's top)."""
    if not value > 0:
        return 1.0
    power = 10.0 ** math.floor(math.log10(value))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * power >= value:
            return m * power
    return 10.0 * power
