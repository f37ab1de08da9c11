"""Bridges, loads and readings: the data calibration and measurement work on (SPEC.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Standard gravity, m/s^2 (ISO 80000-3): a hung mass m pulls with F = m g_n.
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class Bridge:
    """One Wheatstone bridge: its station (1 = nearest the clamp) and axis ('' for 1 axis)."""

    station: int
    axis: str = ""

    @property
    def name(self) -> str:
        """The readings.csv column: ``V1``, ``V2`` ... or ``V1y``, ``V1z`` ... (SPEC.md)."""
        return f"V{self.station}{self.axis}"

    def column(self, counts: bool = False) -> str:
        """Its readings.csv column: ``name`` in volts, ``C1``, ``C1y`` ... in the converter's counts."""
        return "C" + self.name[1:] if counts else self.name


def bridges_for(stations: int, axes: int) -> tuple[Bridge, ...]:
    """The bridges of a sensor in column order."""
    letters = ("",) if axes == 1 else ("y", "z")
    return tuple(Bridge(s, a) for s in range(1, stations + 1) for a in letters)


def axis_force(force, angle, axis: str):
    """The force component a bridge of ``axis`` sees: F, F cos(theta) or F sin(theta)."""
    force = np.asarray(force, dtype=float)
    if axis == "":
        return force
    angle = np.zeros_like(force) if angle is None else np.asarray(angle, dtype=float)
    return force * (np.cos(angle) if axis == "y" else np.sin(angle))


@dataclass(frozen=True)
class LoadSet:
    """Point loads: force (N), position (m) and, for biaxial sensors, angle (rad), per row."""

    force: np.ndarray
    position: np.ndarray
    angle: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.force)

    def repeated(self, repeats: int) -> "LoadSet":
        """Every load ``repeats`` times in a row (r1 r1 r1 r2 r2 r2 ...)."""
        angle = None if self.angle is None else np.repeat(self.angle, repeats)
        return LoadSet(np.repeat(self.force, repeats), np.repeat(self.position, repeats), angle)


@dataclass(frozen=True)
class Readings:
    """A table of bridge readings, SI, as read from readings.csv or simulated.

    ``force``, ``position`` and ``angle`` are the known loads (None when the file gives only
    voltages); ``lines`` are the file lines of the rows, used to name rows in messages.
    """

    bridges: tuple[Bridge, ...]
    voltages: np.ndarray                 # (rows, bridges), V
    force: np.ndarray | None = None      # N
    position: np.ndarray | None = None   # m
    angle: np.ndarray | None = None      # rad
    lines: tuple[int, ...] = ()
    source: str = "readings"
    mass: bool = True                    # the loads are hung masses (written back as mass_g)
    counts: bool = False                 # ``voltages`` hold the converter's counts (columns C1, C2, ...)
    counted: bool = False                # read as counts and converted to volts: the file's columns are C1, C2, ...

    def __len__(self) -> int:
        return self.voltages.shape[0]

    @property
    def axes(self) -> int:
        return 2 if any(b.axis for b in self.bridges) else 1

    @property
    def stations(self) -> int:
        return max(b.station for b in self.bridges)

    @property
    def force_column(self) -> str:
        return "mass_g" if self.mass else "force_N"

    @property
    def file_counts(self) -> bool:
        """Whether the file's bridge columns are counts (C1, C2 ...), converted to volts or not."""
        return self.counts or self.counted

    def column(self, j: int) -> str:
        """Bridge ``j``'s column as the file names it: ``V1``, or ``C1`` in counts."""
        return self.bridges[j].column(self.file_counts)

    def row(self, i: int) -> str:
        """``"line 7"`` (or ``"row 7"`` when there is no file) for messages."""
        return f"line {self.lines[i]}" if self.lines else f"row {i + 1}"

    @property
    def loads(self) -> LoadSet | None:
        if self.force is None or self.position is None:
            return None
        return LoadSet(self.force, self.position, self.angle)
