"""Image error against a reference image: max and mean difference, differing share, PSNR, SSIM.

Images are uint8 (H, W, 3) or (H, W, 4) arrays; differences are in 1/255 units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

SSIM_WINDOW = 7  # scikit-image's default window; smaller images are refused


@dataclass(frozen=True)
class ImageDiff:
    """How far image ``b`` is from reference ``a``.

    ``max_abs``: largest channel difference over RGB(A), in 1/255. ``mean_abs``: mean absolute
    difference per RGB channel, in 1/255. ``share_differing``: share (0..1) of pixels with any
    RGB(A) channel differing. ``psnr``: peak signal-to-noise ratio of RGB in dB, ``inf`` for
    identical colours. ``ssim``: structural similarity of RGB (scikit-image, data range 255),
    1 for identical colours.
    """

    max_abs: int
    mean_abs: float
    share_differing: float
    psnr: float
    ssim: float

    def as_row(self) -> dict[str, float | int]:
        """Flat table columns, named as in every table: ``max_diff_255``, ``mean_diff_255``,
        ``share_differing``, ``psnr_db`` and ``ssim``."""
        return {"max_diff_255": self.max_abs, "mean_diff_255": self.mean_abs,
                "share_differing": self.share_differing, "psnr_db": self.psnr, "ssim": self.ssim}


def _check_image(image, name: str) -> np.ndarray:
    image = np.asarray(image)
    if image.dtype != np.uint8:
        raise TypeError(f"{name} must be a uint8 image, got dtype {image.dtype}")
    if image.ndim != 3 or image.shape[2] not in (3, 4):
        raise ValueError(f"{name} must be (H, W, 3) or (H, W, 4), got shape {image.shape}")
    return image


def difference_map(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """(H, W) uint8: the largest absolute channel difference of each pixel, in 1/255."""
    a, b = _check_image(a, "a"), _check_image(b, "b")
    if a.shape != b.shape:
        raise ValueError(f"images differ in shape: {a.shape} vs {b.shape}")
    return np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2).astype(np.uint8)


def compare_images(a: ArrayLike, b: ArrayLike, mask: ArrayLike | None = None) -> ImageDiff:
    """Compare image ``b`` with reference ``a`` (same shape, uint8, 3 or 4 channels).

    With a boolean (H, W) ``mask`` every statistic covers only the masked pixels (SSIM: the mean
    of scikit-image's SSIM map over them). Refuses differing shapes, non-uint8 images, images
    smaller than 7 × 7 (the SSIM window), a mask of the wrong shape and an empty mask.
    """
    from skimage.metrics import structural_similarity

    a, b = _check_image(a, "a"), _check_image(b, "b")
    if a.shape != b.shape:
        raise ValueError(f"images differ in shape: {a.shape} vs {b.shape}")
    if min(a.shape[:2]) < SSIM_WINDOW:
        raise ValueError(f"images must be at least {SSIM_WINDOW} x {SSIM_WINDOW} pixels for SSIM, "
                         f"got {a.shape[1]} x {a.shape[0]}")
    if mask is None:
        mask = np.ones(a.shape[:2], bool)
    else:
        mask = np.asarray(mask)
        if mask.shape != a.shape[:2] or mask.dtype != bool:
            raise ValueError(f"mask must be a boolean array of shape {a.shape[:2]}, "
                             f"got {mask.dtype} {mask.shape}")
        if not mask.any():
            raise ValueError("mask selects no pixels")
    diff = np.abs(a.astype(np.int16) - b.astype(np.int16))[mask]  # (P, C)
    max_abs = int(diff.max())
    rgb = diff[:, :3].astype(np.float64)
    mean_abs = float(rgb.mean())
    share = float((diff > 0).any(axis=1).mean())
    mse = float((rgb ** 2).mean())
    psnr = math.inf if mse == 0.0 else 10.0 * math.log10(255.0 ** 2 / mse)
    if mse == 0.0:
        ssim = 1.0
    else:
        _, ssim_map = structural_similarity(a[..., :3], b[..., :3], channel_axis=2,
                                            data_range=255, full=True)
        ssim = float(ssim_map[mask].mean())
    return ImageDiff(max_abs=max_abs, mean_abs=mean_abs, share_differing=share, psnr=psnr,
                     ssim=ssim)


def compare_drawn(image: ArrayLike, reference: ArrayLike,
                  background: ArrayLike = (1.0, 1.0, 1.0, 1.0)) -> ImageDiff:
    """:func:`compare_images` of ``image`` against ``reference`` over the pixels either draws
    (differs from ``background``, as in :func:`coverage`): a background both leave empty does
    not count towards the statistics."""
    mask = coverage(image, background) | coverage(reference, background)
    return compare_images(reference, image, mask=mask)


def difference_image(a: ArrayLike, b: ArrayLike, gain: int = 8) -> np.ndarray:
    """(H, W, 4) uint8 opaque grey picture of how ``a`` and ``b`` differ in RGB: white where
    they agree, darker by ``gain`` grey levels per 1/255 of the largest channel difference
    (black from 255 / ``gain`` on)."""
    a, b = _check_image(a, "a"), _check_image(b, "b")
    diff = difference_map(a[..., :3], b[..., :3]).astype(np.int32)
    grey = (255 - np.clip(diff * int(gain), 0, 255)).astype(np.uint8)
    return np.dstack([grey, grey, grey, np.full_like(grey, 255)])


def _background_bytes(background) -> np.ndarray:
    bg = np.asarray(background)
    if bg.ndim != 1 or bg.shape[0] not in (3, 4):
        raise ValueError(f"background must have 3 or 4 components, got {background!r}")
    if np.issubdtype(bg.dtype, np.floating):
        if not np.all((bg >= 0.0) & (bg <= 1.0)):
            raise ValueError(f"float background components must lie in [0, 1], got {background!r}")
        return np.rint(bg * 255.0).astype(np.int16)
    if np.issubdtype(bg.dtype, np.integer):
        if not np.all((bg >= 0) & (bg <= 255)):
            raise ValueError("integer background components must lie in [0, 255], "
                             f"got {background!r}")
        return bg.astype(np.int16)
    raise TypeError(f"background must be numeric, got {background!r}")


def coverage(image: ArrayLike, background: ArrayLike = (1.0, 1.0, 1.0, 1.0),
             tolerance: int = 0) -> np.ndarray:
    """(H, W) bool: pixels whose colour differs from ``background`` by more than ``tolerance``.

    ``background`` has 3 (RGB compared) or 4 (RGBA compared) components: floats in [0, 1] as
    passed to ``Framebuffer.clear``, or integers in [0, 255]. ``tolerance`` is in 1/255.
    """
    image = _check_image(image, "image")
    bg = _background_bytes(background)
    channels = len(bg)
    if channels > image.shape[2]:
        raise ValueError("an RGBA background needs an RGBA image")
    diff = np.abs(image[..., :channels].astype(np.int16) - bg)
    return (diff > tolerance).any(axis=2)


def wire_pixels(image: ArrayLike, wire_color: ArrayLike) -> np.ndarray:
    """(H, W) bool: pixels of exactly ``wire_color`` (RGB in [0, 1]), the wire frame's pixels."""
    colour = np.round(np.asarray(wire_color, np.float64) * 255).astype(np.uint8)
    return (_check_image(image, "image")[..., :3] == colour).all(axis=-1)


def wire_agreement(image: ArrayLike, reference: ArrayLike,
                   wire_color: ArrayLike) -> dict[str, int | float]:
    """How the wire pixels of ``image`` agree with those of ``reference`` (a line-overdraw
    image), with a tolerance of one pixel (3 × 3 dilation, scikit-image):

    * ``wire_recall_1px``: reference wire pixels with an image wire pixel within one pixel;
    * ``wire_precision_1px``: the converse;
    * ``wire_iou_1px``: ``1 / (1/precision + 1/recall − 1)``, the intersection over union when
      matched pixels are counted once on each side (0 when either is 0);
    * ``wire_exact_overlap``: intersection over union without tolerance;
    * the two pixel counts.
    """
    from skimage.morphology import dilation, footprint_rectangle

    a, b = wire_pixels(image, wire_color), wire_pixels(reference, wire_color)
    near = footprint_rectangle((3, 3))
    recall = float((b & dilation(a, near)).sum() / max(b.sum(), 1))
    precision = float((a & dilation(b, near)).sum() / max(a.sum(), 1))
    iou = 0.0 if min(recall, precision) == 0 else 1.0 / (1.0 / precision + 1.0 / recall - 1.0)
    return dict(wire_pixels=int(a.sum()), overdraw_wire_pixels=int(b.sum()),
                wire_recall_1px=recall, wire_precision_1px=precision, wire_iou_1px=iou,
                wire_exact_overlap=float((a & b).sum() / max((a | b).sum(), 1)))


def crack_pixels(image: ArrayLike, background: ArrayLike = (1.0, 1.0, 1.0, 1.0)) -> np.ndarray:
    """(H, W) bool: background pixels enclosed by drawn ones — cracks seen through a surface
    that should be closed (st2005 §4.3), e.g. between elements whose heights disagree.

    A crack that reaches the image border or the outline is not enclosed and is not counted;
    for a height field over a simply connected domain seen from above, every crack between
    elements is enclosed. ``background`` as in :func:`coverage`.
    """
    from scipy.ndimage import binary_fill_holes

    covered = coverage(image, background)
    return binary_fill_holes(covered) & ~covered
