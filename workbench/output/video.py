"""Frames written as a video file, atomically: MP4 (H.264, yuv420p, through imageio-ffmpeg) or an
animated GIF (through pillow, :func:`~workbench.output.figures.save_animation`).

Either is written to a temporary file beside the target (for MP4 with the ``.mp4`` suffix
ffmpeg chooses its container by) and moved onto it with ``os.replace`` only once every frame
is in, so that a run that fails leaves the target as it was and no temporary file behind.

MP4 frames are encoded at constant quality (x264's CRF :data:`MP4_CRF`, close to visually
lossless) in 4:2:0 chroma, which needs an even width and height: odd frame sizes are refused,
never padded or scaled. GIF frames are quantised to a palette of 256 colours each; pillow
merges consecutive identical frames into one.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from .tables import current_umask
from .targets import output_target

FORMATS = (".mp4", ".gif")
MP4_CRF = 18


def video_target(path: str | os.PathLike[str]) -> Path:
    """``path`` as a video to write: refused (ValueError, one line) where it exists and is
    not a regular file (:func:`~workbench.output.targets.output_target`) or does not end
    in one of :data:`FORMATS`."""
    path = output_target(path)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f"output {path}: write an animation as .mp4 (H.264) or .gif, "
                         f"not {path.suffix or 'a file without a suffix'}")
    return path


def check_even(size: tuple[int, int], what: str = "frame size") -> None:
    """Refuse (ValueError) an odd width or height for MP4 (H.264 in 4:2:0 chroma)."""
    if size[0] % 2 or size[1] % 2:
        raise ValueError(f"{what} {size[0]}x{size[1]}: MP4 (H.264, yuv420p) needs an even "
                         f"width and height")


def write_video(path: str | os.PathLike[str], frames: Iterable[np.ndarray],
                fps: float) -> int:
    """Write ``frames`` ((H, W, 3|4) uint8, all of one size) to ``path`` (MP4 or GIF by its
    suffix, :func:`video_target`) at ``fps`` frames per second; returns the frame count.
    MP4 frames are encoded as they come; GIF frames are kept until the last one (a GIF's frame
    delay is whole hundredths of a second: 1/fps rounded). Refused (ValueError): no frames,
    frames of different sizes, a non-positive fps, an odd MP4 frame size."""
    path = video_target(path)
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    if path.suffix.lower() == ".gif":
        from .figures import save_animation

        kept = list(frames)
        save_animation(path, kept, duration_ms=round(1000.0 / fps))
        return len(kept)
    return _write_mp4(path, frames, fps)


def _write_mp4(path: Path, frames: Iterable[np.ndarray], fps: float) -> int:
    """Encode ``frames`` into a temporary ``.mp4`` beside ``path``, then move it there."""
    import imageio_ffmpeg

    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".mp4")
    os.close(fd)
    os.chmod(tmp, 0o666 & ~current_umask())  # mkstemp makes 0600
    writer, shape, count = None, None, 0
    try:
        for frame in frames:
            rgb = np.ascontiguousarray(np.asarray(frame, np.uint8)[..., :3])
            if writer is None:
                shape = rgb.shape
                check_even((shape[1], shape[0]))
                writer = imageio_ffmpeg.write_frames(
                    tmp, (shape[1], shape[0]), fps=fps, codec="libx264", pix_fmt_in="rgb24",
                    pix_fmt_out="yuv420p", quality=None, macro_block_size=1,
                    ffmpeg_log_level="error", output_params=["-crf", str(MP4_CRF)])
                writer.send(None)
            elif rgb.shape != shape:
                raise ValueError(f"frame {count} is {rgb.shape[1]}x{rgb.shape[0]}, the first "
                                 f"{shape[1]}x{shape[0]}: a video's frames are of one size")
            writer.send(rgb)
            count += 1
        if writer is None:
            raise ValueError("no frames to write")
        writer.close()
        writer = None
        os.replace(tmp, output_target(path))
    except BaseException:
        if writer is not None:
            writer.close()
        Path(tmp).unlink(missing_ok=True)
        raise
    return count
