"""What ``workbench render`` checks of a scene and of the image it drew, and how it writes the
image: a PNG, with a colour bar when a field is shown."""

from __future__ import annotations

from pathlib import Path


def write_image(out: Path, image, path, field: str | None, args, title: str,
                scene=None) -> None:
    """``image`` as a PNG at ``out``: with a colour bar of ``field`` when there is one and a
    colour scale, unless ``--raw``; where ``scene`` (the mesh drawn, at ``args.step``) has
    non-finite values of the field, the bar states the no-result colour, their count and
    the parts without any value."""
    from ..output.figures import save_field_figure, save_png
    from ..paths.colormap import no_result_text

    out.parent.mkdir(parents=True, exist_ok=True)
    scale = getattr(path, "scale", None)
    if field is not None and not args.raw and scale is not None:
        no_result = None if scene is None else no_result_text(scene, field, args.step)
        save_field_figure(out, image, value_range=scale.value_range,
                          colormap=path.style.colormap, label=field, units=args.units,
                          title=title, bands=args.bands, no_result=no_result)
    else:
        save_png(out, image)


# the widest model drawn (model units): beyond it the float32 coordinates relative to its
# centre and the matrices that scale them near float32's limit, 3.4e38 (1e38 draws nothing)
FLOAT32_EXTENT = 0.1 * 3.4028235e38


def extent_of(mesh, step: int) -> tuple[float, str]:
    """(extent, words): the largest side of the box of ``mesh``'s referenced nodes at ``step``
    (model units), and words naming it with the node farthest from the nodes' median (the
    stray node that makes the box that wide)."""
    import numpy as np

    nodes = mesh.coordinates(step)
    used = mesh.used_nodes()
    points = nodes[used]
    extent = float(np.max(points.max(axis=0) - points.min(axis=0)))
    distance = np.linalg.norm(points - np.median(points, axis=0), axis=1)
    far = int(used[np.argmax(distance)])
    label = (f"node {int(mesh.node_ids[far])}" if mesh.node_ids is not None
             else f"node index {far}")
    x, y, z = nodes[far]
    return extent, (f"its extent of {extent:.3g} {mesh.units} ({label} at ({x:.3g}, {y:.3g}, "
                    f"{z:.3g}) lies {distance.max():.3g} {mesh.units} from the median node)")


def check_extent(scene, step: int) -> None:
    """Refuse (ValueError) an FE mesh wider than :data:`FLOAT32_EXTENT`: its coordinates
    relative to its centre, and the matrices that scale them, overflow float32 and draw
    nothing."""
    if scene.kind != "mesh":
        return
    extent, words = extent_of(scene, step)
    if extent > FLOAT32_EXTENT:
        raise ValueError(f"{scene.name}: {words} is beyond what float32 coordinates relative "
                         f"to its centre can draw (at most {FLOAT32_EXTENT:.3g})")


def check_drawn(image, scene, camera, size: tuple[int, int], step: int) -> None:
    """Refuse (ValueError, one line) an image in which no pixel differs from the white
    background: nothing of the scene was drawn, so no image is written. For an FE mesh whose
    elements all project thinner than a pixel the line says so, with the model's extent and
    its farthest node: the camera is fitted to the box of every referenced node, so one node
    far out (1e20 mm among millimetre-sized elements) makes the view that wide."""
    import numpy as np

    from ..measurement.images import coverage
    from ..paths.drawing import WHITE

    if coverage(image, WHITE).any():
        return
    why = ""
    if scene.kind == "mesh":
        win = camera.project(scene.coordinates(step), size)[:, :2]
        tri = scene.triangles
        a, b, c = win[tri[:, 0]], win[tri[:, 1]], win[tri[:, 2]]
        ab, ac, bc = b - a, c - a, c - b
        area2 = np.abs(ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0])
        longest = np.max([np.hypot(*e.T) for e in (ab, ac, bc)], axis=0)
        # each triangle's width across its longest edge, in pixels
        widths = np.divide(area2, longest, out=np.zeros_like(area2), where=longest > 0)
        if widths.max() < 1.0:
            why = (f"; every element is thinner than a pixel (the widest {widths.max():.2g} "
                   f"px) in the view fitted to {extent_of(scene, step)[1]}")
    raise ValueError(f"the {size[0]}x{size[1]} image shows nothing of {scene.name}: no pixel "
                     f"differs from the background{why}")
