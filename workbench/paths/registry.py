"""The registry of render paths: every path class by name, and the path a scene is drawn with
by default.

A class derived from :class:`~workbench.paths.base.RenderPath` that sets ``name`` registers
itself on definition; :func:`make_path` makes one by name with its style's options.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from ..gl.camera import Camera
    from ..scene.protocol import Scene


class PathClass(Protocol):
    """A registered path class as the registry sees it: a subclass of
    :class:`~workbench.paths.base.RenderPath` (not imported here: that module imports this one
    to register its subclasses), called with a style to make a path."""

    @property
    def name(self) -> str: ...

    @property
    def style_class(self) -> type: ...

    @property
    def scene_kinds(self) -> frozenset[str]: ...

    @property
    def fixed_options(self) -> frozenset[str]: ...

    @property
    def needs(self) -> frozenset[str]: ...

    def default_camera(self, scene: Scene, size: tuple[int, int], *,
                       view: tuple[float, float] = ..., projection: str = ..., up: str = ...,
                       style: object | None = None) -> Camera: ...

    def __call__(self, style: Any = None) -> Any: ...


PATHS: dict[str, PathClass] = {}

# the path a scene of each kind is drawn with when none is named
DEFAULT_PATHS = {"mesh": "gouraud", "spacetime": "spacetime_pixel", "surface": "fe_normal_map"}


def register(cls: PathClass) -> None:
    """Put path class ``cls`` in the registry under ``cls.name``."""
    PATHS[cls.name] = cls


def path_class(name: str) -> PathClass:
    """The registered path class ``name``; ValueError listing the registry otherwise."""
    try:
        return PATHS[name]
    except KeyError:
        raise ValueError(f"unknown render path {name!r}; known paths: {sorted(PATHS)}") from None


def make_path(name: str, style: object | None = None, **options: Any) -> Any:
    """A new, unprepared path of registry ``name`` with ``style`` (an instance of the path's
    ``style_class``) or, instead, ``options`` naming fields of that class; ValueError for an
    unknown path, or for an option the path does not take (naming it and the known ones)."""
    cls = path_class(name)
    if options:
        if style is not None:
            raise ValueError("give either a style or options, not both")
        style = cls.style_class(**check_options(name, options))
    return cls(style)


def path_options(name: str) -> frozenset[str]:
    """The option names path ``name`` takes: the fields of its ``style_class`` but those the
    path fixes itself (``fixed_options``, e.g. the shading of a spacetime path)."""
    cls = path_class(name)
    return frozenset(cls.style_class.__dataclass_fields__) - cls.fixed_options


def check_options(name: str, options: dict[str, Any]) -> dict[str, Any]:
    """``options`` unchanged when path ``name`` takes every key; ValueError naming the first
    unknown key and the known ones otherwise."""
    known = path_options(name)
    for key in options:
        if key not in known:
            raise ValueError(f"path {name!r} takes no option {key!r}; "
                             f"its options: {', '.join(sorted(known))}")
    return options


def paths_for(kind: str) -> list[str]:
    """The names of the paths that draw scenes of ``kind`` ("mesh", "spacetime", "surface"),
    sorted."""
    return sorted(name for name, cls in PATHS.items() if kind in cls.scene_kinds)


def default_path(scene: Scene, field: str | None = None) -> str:
    """The path ``scene`` is drawn with when none is named: for an FE mesh ``gouraud``, or with
    a ``field`` ``element_color`` (an element field) or ``pixel_color`` (a node field); the
    per-pixel path for a spacetime scene; the normal-map path for a textured surface."""
    if scene.kind == "mesh" and field is not None:
        return "element_color" if field in scene.element_fields else "pixel_color"
    return DEFAULT_PATHS[scene.kind]


# how a refusal names a scene of each kind
SCENE_KIND_NAMES = {"mesh": "an FE mesh", "spacetime": "a spacetime scene",
                    "surface": "a textured surface"}


def scene_path(scene, name: str | None = None, field: str | None = None, *,
               source: str | None = None) -> str:
    """The registry name of the path that draws ``scene``: ``name``, or when none is named the
    :func:`default_path` for ``field``. ValueError for an unknown path, or for one that does
    not draw scenes of ``scene.kind`` (naming the scene as ``source``, default its name)."""
    name = name or default_path(scene, field)
    kinds = path_class(name).scene_kinds
    if scene.kind not in kinds:
        what = SCENE_KIND_NAMES.get(scene.kind, f"a {scene.kind} scene")
        raise ValueError(f"path {name!r} draws {' or '.join(sorted(kinds))} scenes; "
                         f"{source or scene.name!r} is {what}")
    return name
