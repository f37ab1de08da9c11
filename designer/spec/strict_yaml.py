"""YAML as a spec may be written: plain mappings, lists and scalars, each key once.

PyYAML's safe loader accepts what a spec never needs and a hostile file exploits: aliases
(``*name``), which expand a few lines into gigabytes (a "billion laughs"); nesting deep enough to
exhaust the recursion limit; and a key given twice, of which the last silently wins. This loader
refuses each with a message naming the line, and refuses texts larger than ``MAX_BYTES``.

The files that ship with the package (``load_shipped``) are read with libyaml's parser where
PyYAML has it, 5-8 times faster than its pure-Python one; a key given twice is refused there too.
"""

from __future__ import annotations

import yaml

MAX_BYTES = 1_000_000     # a spec is a few hundred bytes; a catalogue file a few tens of kB
MAX_DEPTH = 20            # a spec nests three levels deep


class StrictYamlError(ValueError):
    """What is wrong, with the line it is on."""


class _NoKeyTwice:
    """The loaders' mappings: a key given twice is refused with the line of each."""

    def construct_mapping(self, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                hash(key)
            except TypeError:
                continue  # the base loader says what is wrong with an unhashable key
            if key in seen:
                raise StrictYamlError(f"line {key_node.start_mark.line + 1}: the key {key!r} is given twice "
                                      f"(first at line {seen[key] + 1}); give it once")
            seen[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)


class _Loader(_NoKeyTwice, yaml.SafeLoader):
    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise StrictYamlError(f"line {event.start_mark.line + 1}: YAML aliases (*{event.anchor}) are not "
                                  "allowed; write the value out")
        self._depth = getattr(self, "_depth", 0) + 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise StrictYamlError(f"line {mark.line + 1}: nested more than {MAX_DEPTH} levels deep")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


class _ShippedLoader(_NoKeyTwice, getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    pass


for _cls in (_Loader, _ShippedLoader):
    _cls.add_constructor("tag:yaml.org,2002:map", _cls.construct_yaml_map)


def load(text: str):
    """The YAML document in ``text``; StrictYamlError or yaml.YAMLError when it is not one a spec may be."""
    if len(text.encode("utf-8", errors="replace")) > MAX_BYTES:
        raise StrictYamlError(f"the file is {len(text) / 1e6:.1f} MB; a spec or catalogue file is at most "
                              f"{MAX_BYTES / 1e6:g} MB")
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - _Loader is a SafeLoader


def load_as(text: str, source: str, error: type[Exception]):
    """``load(text)``, its failure raised as ``error`` with the one-line message, led by ``source``
    (the file as the user named it)."""
    try:
        return load(text)
    except StrictYamlError as exc:
        raise error(f"{source}: {exc}") from exc
    except yaml.YAMLError as exc:
        raise error(f"{source}: {syntax_error(exc)}") from exc


def load_shipped(text: str):
    """A YAML file that ships with the package: read with libyaml's parser where PyYAML has it,
    a key given twice refused (StrictYamlError); yaml.YAMLError when it is not YAML."""
    return yaml.load(text, Loader=_ShippedLoader)  # noqa: S506 - a SafeLoader, on the package's own files


def syntax_error(exc) -> str:
    """A YAML error of PyYAML (``yaml.YAMLError``) on one line: where and what, as ``"YAML syntax
    error at line 3, column 7: ..."``."""
    mark = getattr(exc, "problem_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
    problem = getattr(exc, "problem", None) or "invalid YAML"
    context, start = getattr(exc, "context", None), getattr(exc, "context_mark", None)
    if context and start is not None and (mark is None or start.line != mark.line):
        problem += f" ({context} that starts at line {start.line + 1}, column {start.column + 1})"
    return " ".join(f"YAML syntax error{where}: {problem}".split())
