"""Animations of a result file (``ancf animate``, SPEC section 2): the whole mesh the file
holds (every body, force element, point mass and joint as /model/mesh draws them) moving
through a dynamic run, or a mode or buckling shape oscillating about the static state it
was computed at, with the time stamp (or the mode's frequency or load factor) on every
frame.

Seen in one plane: the one of the mesh's two largest extents over the run, or the plane
asked for (``view = 'xy' | 'yz' | 'zx'``). Written with matplotlib's writers: MP4 through
ffmpeg when it is installed, a GIF (Pillow) otherwise; an MP4 asked for without ffmpeg is
refused with that advice."""
from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter  # noqa: E402

from .errors import InputError  # noqa: E402
from .plots import _mesh_segments  # noqa: E402

#: the planes a view may name, as (horizontal, vertical) coordinate indices
VIEWS = {"xy": (0, 1), "yz": (1, 2), "zx": (2, 0)}
#: frames of a mode's oscillation (one period)
MODE_FRAMES = 36
#: the most frames of a dynamic run drawn (rows are skipped evenly beyond it)
MAX_FRAMES = 100


def _style(segment: np.ndarray) -> dict:
    from .plots import mesh_style
    return mesh_style(segment)


def _plane(points: np.ndarray, view: str) -> tuple[int, int]:
    """The two coordinates drawn: the view's, or the mesh's two largest extents (over
    every frame), in the order x, y, z."""
    if view != "auto":
        if view not in VIEWS:
            raise InputError(f"view {view!r} must be 'auto' or one of {', '.join(VIEWS)}",
                             key="view")
        return VIEWS[view]
    extent = np.ptp(points.reshape(-1, 3), axis=0)
    first, second = sorted(np.argsort(extent)[-2:])
    return int(first), int(second)


def _frames(h5: h5py.File, path: Path, mode: int | None) -> tuple[np.ndarray, list[str], str]:
    """(frames[nf, npoints, 3], a label per frame, the title) of a dynamic run, or of mode
    ``mode`` (1-based) of a modal or buckling analysis oscillating about its static state."""
    title = h5.attrs.get("title", path.stem)
    title = title.decode() if isinstance(title, bytes) else str(title)
    if "model/mesh" not in h5:
        raise InputError("the file has no mesh to animate (/model/mesh: written with "
                         "output.xdmf = .true., the default)", file=str(path))
    if mode is None:
        if "dynamic/mesh_nodes" not in h5:
            eigen = [g for g in ("modal", "buckling") if g in h5]
            hint = f"; it holds a {eigen[0]} analysis: ask for a shape with --mode N" \
                if eigen else ""
            raise InputError(f"no dynamic run to animate (no /dynamic/mesh_nodes){hint}",
                             file=str(path))
        nodes = h5["dynamic/mesh_nodes"]
        rows = h5["dynamic/mesh_rows"][()]
        count = min(len(rows), nodes.shape[0])
        pick = np.unique(np.linspace(0, count - 1, min(count, MAX_FRAMES)).round().astype(int))
        times = h5["dynamic/time"][()][rows[pick]]
        return nodes[pick.tolist()], [f"t = {t:.3f} s" for t in times], title
    group = next((g for g in ("modal", "buckling") if g in h5 and "mesh_shapes" in h5[g]), None)
    if group is None:
        raise InputError("--mode needs a modal or buckling analysis in the file (no "
                         "/modal or /buckling mesh shapes)", file=str(path))
    shapes = h5[f"{group}/mesh_shapes"]
    if not 1 <= mode <= shapes.shape[0]:
        raise InputError(f"--mode {mode}: the file holds modes 1 to {shapes.shape[0]}",
                         file=str(path))
    static = h5[f"{group}/mesh_static"][()]
    shape = shapes[mode - 1]
    size = max(float(np.ptp(static, axis=0).max()), 1e-12)
    phase = np.sin(2 * np.pi * np.arange(MODE_FRAMES) / MODE_FRAMES)
    frames = static[None] + 0.1 * size * phase[:, None, None] * shape[None]
    if group == "modal":
        value = f"mode {mode}: {h5['modal/frequency'][mode - 1]:.4g} Hz"
    else:
        value = f"buckling mode {mode}: load factor {h5['buckling/load_factor'][mode - 1]:.4g}"
    return frames, [f"{value} (largest displacement a tenth of the model)"] * MODE_FRAMES, title


def animate(h5_path: str | Path, output: str | Path | None = None, *, mode: int | None = None,
            view: str = "auto", fps: int = 24) -> Path:
    """Write an animation of a result file: its dynamic run, or with ``mode`` (1-based)
    that mode of its modal or buckling analysis. ``output``: .gif or .mp4 (default: a GIF
    beside the file, or an MP4 when ffmpeg is installed). Returns the file written."""
    path = Path(h5_path)
    if not path.is_file():
        raise InputError("result file not found", file=str(path))
    if output is None:
        suffix = "_mode{}".format(mode) if mode is not None else ""
        output = path.with_name(path.stem + suffix + (".mp4" if shutil.which("ffmpeg")
                                                      else ".gif"))
    output = Path(output)
    if output.suffix.lower() not in (".gif", ".mp4"):
        raise InputError(f"{output}: an animation is a .gif or an .mp4", key="output")
    if output.suffix.lower() == ".mp4" and not shutil.which("ffmpeg"):
        raise InputError(f"{output}: writing MP4 needs ffmpeg, which is not installed "
                         "(apt install ffmpeg); ask for a .gif instead", key="output")
    with h5py.File(path, "r") as h5:
        frames, labels, title = _frames(h5, path, mode)
        segments = _mesh_segments(h5)
    horizontal, vertical = _plane(frames, view)
    fig, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    flat = frames.reshape(-1, 3)
    low, high = flat.min(axis=0), flat.max(axis=0)
    pad = 0.05 * max(float((high - low).max()), 1e-12)
    ax.set_xlim(low[horizontal] - pad, high[horizontal] + pad)
    ax.set_ylim(low[vertical] - pad, high[vertical] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(f"{'xyz'[horizontal]} (m)")
    ax.set_ylabel(f"{'xyz'[vertical]} (m)")
    ax.grid(alpha=0.3)
    for seg in segments:  # the first frame as a grey ghost
        ax.plot(frames[0][seg, horizontal], frames[0][seg, vertical], color="0.8", lw=0.8,
                **_style(seg))
    lines = [ax.plot([], [], color="C0", lw=1.5, **_style(seg))[0] for seg in segments]
    stamp = ax.set_title("", fontsize=9)
    fig.suptitle(title, fontsize=10)

    def draw(k: int):
        for line, seg in zip(lines, segments):
            line.set_data(frames[k][seg, horizontal], frames[k][seg, vertical])
        stamp.set_text(labels[k])
        return [*lines, stamp]

    movie = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    writer = FFMpegWriter(fps=fps) if output.suffix.lower() == ".mp4" else PillowWriter(fps=fps)
    output.parent.mkdir(parents=True, exist_ok=True)
    temp = output.with_name(f".{output.stem}.partial{output.suffix}")
    try:
        movie.save(str(temp), writer=writer, dpi=80)
        temp.replace(output)
    finally:
        plt.close(fig)
        temp.unlink(missing_ok=True)
    return output
