"""The CAD kernel's start without the whole of VTK.

cadquery's shapes module imports OCP's VTK bridge (``OCP.IVtkOCC``), which imports the ``vtk``
module, and that imports every VTK module: 0.3-0.5 s of the kernel's 1.3-1.8 s start
(``python -X importtime -c "import cadquery"``), for a bridge fpdesign never uses (it
tessellates with OCCT and draws with matplotlib). ``defer_vtk`` puts in its place a module that
imports the real one on the first use of any of its names, so that whatever does use it sees no
difference. It is called when ``designer.outputs.cad`` is first imported, before any cadquery.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import types


class _OnFirstUse(types.ModuleType):
    """``vtk``, imported when one of its names is first asked for."""

    def __getattr__(self, name: str):
        if name == "__path__":   # (the import system asking whether it is a package: it is not)
            raise AttributeError(name)
        if sys.modules.get("vtk") is self:
            del sys.modules["vtk"]
        return getattr(importlib.import_module("vtk"), name)


def defer_vtk() -> None:
    """Put a ``vtk`` that imports itself on first use in sys.modules, unless it is imported
    already or not installed (cadquery then fails as it would have)."""
    if "vtk" not in sys.modules and "cadquery" not in sys.modules and importlib.util.find_spec("vtk") is not None:
        sys.modules["vtk"] = _OnFirstUse("vtk")
