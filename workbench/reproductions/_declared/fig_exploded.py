"""The tables and claims of :mod:`workbench.reproductions.fig_exploded` (ghost2013): the view
sweep, the comparison with uniform and fixed-offset explosions, and the car's parts."""

from __future__ import annotations

from workbench.experiment.declare import Claim, Column, Declaration, Table
from workbench.experiment.report import num, span

SCENE = Column("scene", "", "the scene exploded: the generated box of panels or the car")
FOCUS = Column("focus_part", "", "the part to reveal (the object of interest)")
SWEEP_DEG = Column("sweep_deg", "°", "θ, the angle between the view direction and the split "
                   "plane (0: the plane's normal perpendicular to the view)")

TABLE = Table(
    "table",
    SCENE, FOCUS,
    Column("plane", "", "the split plane: manual, or auto (chosen for the view)"),
    Column("ratio_exponent", "", "p: the halves' speed is proportional to r^p"),
    Column("normal", "", "the split plane's unit normal, x,y,z"),
    Column("view_to_plane_deg", "°", "the angle between the view and the plane used"),
    SWEEP_DEG,
    Column("frames", "", "frames animated (N)"),
    Column("frames_to_reveal", "", "first frame whose occlusion ratio r <= 0.01 (frame 0 at "
           "offset 0); \"not within N\" otherwise"),
    Column("offset_at_reveal_over_o_max", "", "each half's offset at the reveal over o_max "
           "(the bounding-box diagonal)"),
    Column("final_r", "", "the occlusion ratio r after the last step (0: fully revealed)"),
    Column("final_offset_over_o_max", "", "each half's offset at the end over o_max"),
    Column("final_phase", "", "the animation's phase at the end (\"hold\": halted revealed)"),
    Column("o_max", "mm", "the bounding-box diagonal, the largest offset"),
    Column("final_alpha", "", "the front half's opacity at the end"),
    Column("visible_through_ghost_pct", "%", "share of the object's pixels showing through the "
           "ghosted front half at the end"),
    Column("draw_gpu_ms", "ms", "median GPU time of a frame's draw (not comparable on "
           "llvmpipe)"),
    Column("draw_wall_ms", "ms", "median wall time of a frame's draw without its occlusion "
           "count"),
    Column("counted_in_frame_pct", "%", "share of the frames whose occlusion was counted as "
           "they were drawn"),
    Column("occlusion_wall_ms", "ms", "median wall time the occlusion count adds to a frame"),
    Column("occlusion_over_draw", "×", "occlusion_wall_ms over draw_wall_ms"),
    Column("separate_pass_gpu_ms", "ms", "median GPU time of the separate occlusion pass"),
    Column("separate_pass_wall_ms", "ms", "median wall time of the separate occlusion pass"),
    Column("separate_over_draw", "×", "separate_pass_wall_ms over draw_wall_ms"),
    Column("closed_form_reveal_over_o_max", "", "the box's reveal offset from the closed form "
           "a + (a + B) tan θ, over o_max"),
    Column("measured_reveal_over_o_max", "", "the smallest offset with r <= 0.01 (bisection), "
           "over o_max"),
)

COMPARE = Table(
    "compare",
    SCENE, FOCUS, SWEEP_DEG,
    Column("displacement", "mm", "D: each half's offset at the automatic plane's end (p = 1)"),
    Column("displacement_over_o_max", "", "D over o_max"),
    Column("occlusion_driven_revealed", "", "revealed share 1 - r of the occlusion-driven "
           "explosion"),
    Column("uniform_revealed", "", "revealed share 1 - r of a uniform explosion by D"),
    Column("fixed_offset_manual_plane_revealed", "", "revealed share 1 - r at the fixed offset "
           "D along the manual plane"),
    Column("beats_uniform", "", "whether the occlusion-driven explosion reveals more than the "
           "uniform one"),
    Column("beats_fixed_offset", "", "whether it reveals more than the fixed offset"),
)

CAR_PARTS = Table(
    "car_parts",
    Column("part", "", "the car's part"),
    Column("p_unocc", "px", "the part's pixels drawn alone"),
    Column("p_occ", "px", "the part's pixels visible in the assembly"),
    Column("r", "", "occlusion ratio 1 - p_occ / p_unocc at offset 0"),
)


def reveal_claims(tables) -> list[str]:
    """Per scene: views revealing the part, frames to reveal, and the occlusion count's cost."""
    out = []
    rows = tables("table")
    for scene in dict.fromkeys(r["scene"] for r in rows):
        mine = [r for r in rows if r["scene"] == scene]
        # "not within N" where the part was not revealed: the store keeps the column as text
        frames = [int(r["frames_to_reveal"]) for r in mine
                  if str(r["frames_to_reveal"]).isdigit()]
        out.append(f"{scene}: part {mine[0]['focus_part']} revealed in {len(frames)} of "
                   f"{len(mine)} views (up to {num(max(r['sweep_deg'] for r in mine))}° from "
                   f"the split plane), within {max(frames) if frames else 'n/a'} frames; the "
                   f"in-frame count costs {span([r['occlusion_over_draw'] for r in mine])}× the "
                   f"draw, a separate pass {span([r['separate_over_draw'] for r in mine])}× "
                   f"(separate measurements)")
    return out


def reveal_headline(tables) -> list[str]:
    """The car (else the first scene): views revealing the part and the occlusion count's
    cost."""
    rows = tables("table")
    if not rows:
        return []
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    scene = "car" if "car" in scenes else scenes[0]
    mine = [r for r in rows if r["scene"] == scene]
    frames = [int(r["frames_to_reveal"]) for r in mine if str(r["frames_to_reveal"]).isdigit()]
    return [f"{scene}: part {mine[0]['focus_part']} revealed in {len(frames)} of {len(mine)} "
            f"views, within {max(frames) if frames else 'n/a'} frames; counting occlusion costs "
            f"{span([r['occlusion_over_draw'] for r in mine])}× the draw"]


DECLARED = Declaration(
    paper="ghost2013",
    tables=(TABLE, COMPARE, CAR_PARTS),
    claims=(Claim("views revealing the focus part and the occlusion count's cost",
                  {"table": ("scene", "focus_part", "frames_to_reveal", "sweep_deg",
                             "occlusion_over_draw", "separate_over_draw")},
                  reveal_claims),),
    headline=Claim("views revealing the focus part and the occlusion count's cost",
                   {"table": ("scene", "focus_part", "frames_to_reveal",
                              "occlusion_over_draw")},
                   reveal_headline),
)
