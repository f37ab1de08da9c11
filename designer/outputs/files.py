"""Writing outputs so that nothing half-written is ever left behind."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
import tempfile
from pathlib import Path


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder. A path that exists
    and is not a regular file (``/dev/null``, a FIFO, a terminal) is written directly: replacing it
    would put a regular file in the place of a device."""
    path = Path(path)
    if is_special(path):
        try:
            with open(path, "wb") as fh:
                fh.write(data)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(path)) from exc
        return path
    _not_a_folder(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, file_mode())  # mkstemp makes 0600; outputs follow the umask
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    return path


def _not_a_folder(path: Path) -> None:
    """IsADirectoryError naming ``path`` when a file is to be written where a folder is (the
    temporary sibling would be written and then fail to replace it, naming itself)."""
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "it is a folder; give a file name", str(path))


def is_special(path: Path) -> bool:
    """True for an existing path that is neither a regular file nor a folder: a device, a FIFO."""
    return path.exists() and not path.is_file() and not path.is_dir()


def move_into_place(tmp: Path, target: Path) -> None:
    """``os.replace(tmp, target)``, except that a device or FIFO at ``target`` receives the
    content instead of being replaced by a regular file."""
    if is_special(target):
        with open(tmp, "rb") as src, open(target, "wb") as dst:
            shutil.copyfileobj(src, dst)
        os.unlink(tmp)
    else:
        os.replace(tmp, target)


def file_mode() -> int:
    """The permissions an ordinary new file gets (temporary files are private until moved)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def temporary_sibling(path: Path):
    """A temporary file name next to ``path`` with ``file_mode()``, for writers that need a path
    (move it into place with ``os.replace``); removed again unless it was moved."""
    _not_a_folder(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, file_mode())
    try:
        yield Path(tmp)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | os.PathLike, obj) -> Path:
    return atomic_write_text(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")


@contextlib.contextmanager
def staged_directory(target: str | os.PathLike, stale=()):
    """Yield a scratch folder; on success its files are moved into ``target``, and the files of
    ``stale`` (names relative to ``target``: a previous run's outputs) that this run did not write
    again are removed, so that the folder holds one run's outputs.

    If the block raises, the scratch folder is removed and ``target`` is left as it was.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        yield scratch
        target.mkdir(parents=True, exist_ok=True)
        written = set()
        for item in sorted(scratch.rglob("*")):
            if item.is_file():
                name = item.relative_to(scratch)
                dest = target / name
                dest.parent.mkdir(parents=True, exist_ok=True)
                os.replace(item, dest)
                written.add(name.as_posix())
        for name in set(stale) - written:
            old = target / name
            if old.resolve().parent == target.resolve() and old.is_file():  # names in the folder itself
                with contextlib.suppress(OSError):
                    old.unlink()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def previous_outputs(folder: Path) -> set:
    """The files an earlier run listed in ``folder/design.json`` (``files``), with design.json and
    report.md; empty when the folder holds no readable design.json. A name that leads out of the
    folder is never removed: ``staged_directory`` removes only files directly in it."""
    import json

    try:
        files = json.loads((Path(folder) / "design.json").read_text(encoding="utf-8")).get("files", {})
    except (OSError, ValueError, AttributeError, RecursionError):
        return set()
    names = {"design.json", "report.md"}
    if isinstance(files, dict):
        for value in files.values():
            for name in (value if isinstance(value, list) else [value]):
                if isinstance(name, str) and name:
                    names.add(name)
    return names
