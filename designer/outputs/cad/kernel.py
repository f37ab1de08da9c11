"""The CAD kernel's start without the libraries cadquery loads for what fpdesign never uses.

cadquery's start (``python -X importtime -c "import cadquery"``) imports, besides the OCCT
kernel itself:

- OCP's VTK bridge (``OCP.IVtkOCC``), which imports the ``vtk`` module, and that imports every
  VTK module (0.3-0.5 s);
- the VTK modules of its viewers and VTK exporters (``vtkmodules.*``), ezdxf for DXF files,
  casadi for its assembly constraints and nlopt for its sketch constraints (together a quarter of
  what is left).

fpdesign tessellates with OCCT, draws with matplotlib and writes STEP and STL: none of those.
``defer_vtk`` puts in place of ``vtk`` a module that imports the real one on the first use of any
of its names. ``defer_extras`` makes the first import of cadquery see, in place of the others, a
module whose names (``from vtkmodules.vtkRenderingCore import vtkActor``) import the real module
on their first real use (a call, an attribute of a call's result, ``isinstance``); the stand-in
modules are gone from ``sys.modules`` once cadquery is imported, so that any later import gets the
real ones. Both are called when ``designer.outputs.cad`` is first imported, before any cadquery;
whatever uses those libraries through their names sees no difference but the time it is first
used. OCP's VTK bridge (``Shape.toVtkPolyData``, cadquery's viewers) is the exception: its C++
needs the VTK modules loaded before it is called, so a program that uses it imports ``vtk``
before ``designer.outputs.cad`` (nothing is deferred then).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types

#: imported by cadquery's own modules, used only by features fpdesign does not use
EXTRAS = ("vtkmodules", "ezdxf", "casadi", "nlopt")


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


class _Name:
    """``module.name[.attr...]`` of a module not imported yet: the real object, imported on its
    first real use. An attribute of it is another such name (a default argument such as
    ``units.MM`` stays unimported); it has no special attributes of its own."""

    __slots__ = ("_module", "_names", "_real")

    def __init__(self, module: str, names: tuple):
        self._module, self._names, self._real = module, names, None

    def _resolve(self):
        if self._real is None:
            obj, path = importlib.import_module(self._module), self._module
            for name in self._names:
                path = f"{path}.{name}"
                try:
                    obj = getattr(obj, name)
                except AttributeError:   # a submodule its package does not import itself
                    obj = importlib.import_module(path)
            self._real = obj
        return self._real

    def __getattr__(self, name: str):
        if name.startswith("__"):   # (what typing and the import system ask of any object)
            raise AttributeError(name)
        return _Name(self._module, self._names + (name,))

    def __call__(self, *args, **kwargs):
        # (arguments may be such names too: defaults such as ``doc_units=units.MM``)
        real = lambda a: a._resolve() if isinstance(a, _Name) else a   # noqa: E731
        return self._resolve()(*map(real, args), **{k: real(v) for k, v in kwargs.items()})

    def __getitem__(self, key):
        return self._resolve()[key]

    def __instancecheck__(self, obj) -> bool:
        return isinstance(obj, self._resolve())

    def __subclasscheck__(self, cls) -> bool:
        return issubclass(cls, self._resolve())

    def __mro_entries__(self, bases):
        return (self._resolve(),)

    def __repr__(self) -> str:
        return f"<{'.'.join((self._module,) + self._names)}, imported on first use>"


class _StandIn(types.ModuleType):
    """A module of EXTRAS while cadquery imports: its names are ``_Name``s."""

    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        return _Name(self.__name__, (name,))


class _Extras(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds a ``_StandIn`` for every module of ``roots`` (and below) while installed."""

    def __init__(self, roots: tuple):
        self.roots = roots
        self.made: list[str] = []

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in self.roots:
            return importlib.machinery.ModuleSpec(name, self, is_package=True)
        return None

    def create_module(self, spec):
        module = _StandIn(spec.name)
        module.__path__ = []
        self.made.append(spec.name)
        return module

    def exec_module(self, module) -> None:
        pass


class _CadqueryLoader(importlib.abc.Loader):
    """cadquery's own loader, run with the stand-ins of ``_Extras`` in place."""

    def __init__(self, loader, roots: tuple):
        self._loader, self._roots = loader, roots

    def __getattr__(self, name: str):
        return getattr(self._loader, name)

    def create_module(self, spec):
        return self._loader.create_module(spec)

    def exec_module(self, module) -> None:
        extras = _Extras(tuple(r for r in self._roots if r not in sys.modules))
        sys.meta_path.insert(0, extras)
        try:
            self._loader.exec_module(module)
        finally:
            sys.meta_path.remove(extras)
            for name in extras.made:
                if isinstance(sys.modules.get(name), _StandIn):
                    del sys.modules[name]


class _FirstCadquery(importlib.abc.MetaPathFinder):
    """Hands the first import of cadquery to ``_CadqueryLoader``, then steps aside."""

    def find_spec(self, name, path=None, target=None):
        if name != "cadquery":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            spec.loader = _CadqueryLoader(spec.loader, EXTRAS)
        return spec


def defer_extras() -> None:
    """Make the first import of cadquery defer EXTRAS (unless cadquery is imported already)."""
    if "cadquery" not in sys.modules and not any(isinstance(f, _FirstCadquery) for f in sys.meta_path):
        sys.meta_path.insert(0, _FirstCadquery())
