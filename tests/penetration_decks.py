"""Keyword decks of shell sheets with a known penetration answer (crash2000 §4.1), written as
text: the decks of the penetration tests of the algorithm, the flange path and the command."""

from fractions import Fraction

STEP = 5.0  # mm between nodes of every sheet


def sheet(xs, ys, z_of_x, first_node: int):
    """Nodes ``(id, x, y, z)`` and quads (node ids) of a sheet over the grid xs x ys whose
    height is z_of_x(x) (text, 6 decimals)."""
    nodes, ids = [], {}
    for j, y in enumerate(ys):
        for i, x in enumerate(xs):
            ids[i, j] = first_node + len(nodes)
            nodes.append((ids[i, j], x, y, z_of_x(x)))
    quads = [(ids[i, j], ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1])
             for j in range(len(ys) - 1) for i in range(len(xs) - 1)]
    return nodes, quads


def deck_text(sheets, thickness, offset=(0.0, 0.0, 0.0), parameters=()):
    """A keyword deck: part k + 1 (section k + 1, thickness ``thickness[k]``, text or number)
    holds sheet k; every coordinate moved by ``offset``."""
    lines = ["*KEYWORD", *parameters]
    for k, t in enumerate(thickness):
        lines += ["*PART", f"sheet {k + 1}", f"{k + 1:10d}{k + 1:10d}{1:10d}",
                  "*SECTION_SHELL", f"{k + 1:10d}",
                  "".join(f"{t if isinstance(t, str) else f'{t:.4f}':>10}" for _ in range(4))]
    lines.append("*NODE")
    for nodes, _ in sheets:
        lines += [f"{n:8d}{x + offset[0]:16.6f}{y + offset[1]:16.6f}{float(z) + offset[2]:16.6f}"
                  for n, x, y, z in nodes]
    lines.append("*ELEMENT_SHELL")
    eid = 1
    for k, (_, quads) in enumerate(sheets):
        for q in quads:
            lines.append(f"{eid:8d}{k + 1:8d}" + "".join(f"{n:8d}" for n in q))
            eid += 1
    lines.append("*END")
    return "\n".join(lines) + "\n"


def grid(lo, hi):
    """lo, lo + STEP, ..., hi."""
    return [lo + STEP * i for i in range(int(round((hi - lo) / STEP)) + 1)]


YS = grid(0.0, 10.0)


def parallel_sheets(gap: float):
    """Sheet 1 at z = 0 over x 0..50, sheet 2 at z = gap over x 20..70 (node ids from 1 and
    1001); the overlap is x 20..50."""
    return [sheet(grid(0, 50), YS, lambda x: 0.0, 1),
            sheet(grid(20, 70), YS, lambda x: gap, 1001)]


def write(tmp_path, name, text):
    """``text`` written to ``tmp_path / name``; the path."""
    path = tmp_path / name
    path.write_text(text)
    return path


def tilted_sheets():
    """Sheet 1 flat at z = 0, sheet 2 over the same x 0..40 rising as z = 0.7 + x/16; both
    2 mm thick, so a node penetrates where it is nearer than 2 mm to the other sheet."""
    def z2(x):
        return f"{float(Fraction(7, 10) + Fraction(x).limit_denominator() / 16):.6f}"
    return [sheet(grid(0, 40), YS, lambda x: "0.000000", 1),
            sheet(grid(0, 40), YS, z2, 1001)]
