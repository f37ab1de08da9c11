"""Figures as SVG or PNG: bytes that are the same for the same design, and files written so
that nothing half-written is left behind."""

from __future__ import annotations

import io
import os
from pathlib import Path

from designer.outputs.files import atomic_write_bytes


#: zlib's fastest level for PNG files (Pillow's default is 6): the same pixels, written in about
#: half the time (0.25 s against 0.43 s for the operating-region plot) for files ~10 % larger.
PNG_OPTIONS = {"pil_kwargs": {"compress_level": 1}}


def savefig_options(fmt: str) -> dict:
    """``savefig``'s keywords for ``fmt``: no date in an SVG, fast compression for a PNG."""
    return {"metadata": {"Date": None}} if fmt == "svg" else dict(PNG_OPTIONS) if fmt == "png" else {}


def figure_bytes(fig, fmt: str, dpi: int = 150) -> bytes:
    """``fig`` as ``fmt`` (svg or png). SVG text is drawn as outlines, so that it looks the same
    in every viewer, and carries no date, so that the same design gives the same file."""
    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "path", "svg.hashsalt": "fpdesign"}):
        fig.savefig(buf, format=fmt, dpi=dpi, facecolor="white", **savefig_options(fmt))
    return buf.getvalue()


def save_figure(fig, path: str | os.PathLike, fmt: str, dpi: int = 150) -> Path:
    """Write ``fig`` as ``fmt`` (svg or png) so that no half-written file is left behind."""
    return atomic_write_bytes(path, figure_bytes(fig, fmt, dpi))
