"""Figures as SVG or PNG: bytes that are the same for the same design, and files written so
that nothing half-written is left behind."""

from __future__ import annotations

import io
import os
from pathlib import Path

from designer.outputs.files import atomic_write_bytes


def figure_bytes(fig, fmt: str, dpi: int = 150) -> bytes:
    """``fig`` as ``fmt`` (svg or png). SVG text is drawn as outlines, so that it looks the same
    in every viewer, and carries no date, so that the same design gives the same file."""
    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "path", "svg.hashsalt": "fpdesign"}):
        fig.savefig(buf, format=fmt, dpi=dpi, metadata={"Date": None} if fmt == "svg" else None,
                    facecolor="white")
    return buf.getvalue()


def save_figure(fig, path: str | os.PathLike, fmt: str, dpi: int = 150) -> Path:
    """Write ``fig`` as ``fmt`` (svg or png) so that no half-written file is left behind."""
    return atomic_write_bytes(path, figure_bytes(fig, fmt, dpi))
