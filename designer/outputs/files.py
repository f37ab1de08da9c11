"""Writing outputs so that nothing half-written is ever left behind."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
import tempfile
from pathlib import Path

#: Characters of a target's name kept in the name of its temporary file or scratch folder (which
#: adds a dot, eight random characters and a suffix): a name near the 255 bytes a file name may
#: have then fails, if at all, as itself and not as its longer temporary.
TEMP_NAME_CHARS = 40


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder. A path that exists
    and is not a regular file (``/dev/null``, a FIFO, a terminal) is written directly: replacing it
    would put a regular file in the place of a device."""
    from designer import interrupt

    path = Path(path)
    if is_special(path):
        try:
            with open(path, "wb") as fh:
                fh.write(data)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(path)) from exc
        return path
    _not_a_folder(path)
    with naming(path), _folders_for(path):
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path), dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.chmod(tmp, file_mode())  # mkstemp makes 0600; outputs follow the umask
            with interrupt.held():
                os.replace(tmp, path)
                interrupt.wrote(path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise
    return path


@contextlib.contextmanager
def _folders_for(path: Path):
    """The folders ``path`` needs (``make_folders``), removed again if the block fails: a write
    that fails (a name too long, a full disk, a signal) leaves no new empty folder behind."""
    from designer import interrupt

    with interrupt.held():
        made = make_folders(path.parent)
    try:
        yield
    except BaseException:
        with interrupt.held():
            remove_folders(made)
        raise


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
        with naming(target):
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


def temp_prefix(path: Path) -> str:
    """The start of the name of ``path``'s temporary sibling: hidden, and recognisably its own."""
    return f".{path.name[:TEMP_NAME_CHARS]}."


@contextlib.contextmanager
def naming(path: Path):
    """OSErrors raised in the block name ``path``, the file the user asked for, instead of the
    temporary file beside it."""
    try:
        yield
    except OSError as exc:
        exc.filename, exc.filename2 = str(path), None
        raise


@contextlib.contextmanager
def temporary_sibling(path: Path):
    """A temporary file name next to ``path`` with ``file_mode()``, for writers that need a path
    (move it into place with ``os.replace``); removed again unless it was moved. An OSError in the
    block names ``path``."""
    _not_a_folder(path)
    with naming(path), _folders_for(path):
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path), suffix=".tmp", dir=path.parent)
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


def same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """True when ``a`` and ``b`` name one file: the same path spelt differently, through a
    symbolic link, or (both existing) a hard link."""
    pa, pb = Path(a), Path(b)
    try:
        if pa.exists() and pb.exists():
            return os.path.samefile(pa, pb)
    except OSError:
        return False
    return pa.resolve() == pb.resolve()


def make_folders(folder: Path) -> list[Path]:
    """``folder.mkdir(parents=True, exist_ok=True)``; returns the folders it created, outermost
    first, for ``remove_folders`` should the run fail."""
    folder = Path(folder)
    missing = []
    while not os.path.lexists(folder) and folder.parent != folder:
        missing.append(folder)
        folder = folder.parent
    if not folder.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "it is a file, not a folder", str(folder))
    made = []
    try:
        for path in reversed(missing):
            path.mkdir()
            made.append(path)
    except BaseException:
        remove_folders(made)
        raise
    return made


def remove_folders(made) -> None:
    """Remove the folders ``make_folders`` created, innermost first, where they are still empty."""
    for path in reversed(list(made)):
        with contextlib.suppress(OSError):
            path.rmdir()


def check_targets(targets) -> None:
    """Before anything is moved: OSError naming the target when a folder is where a file is to
    go, or a file where one of its folders is to be."""
    for target in targets:
        target = Path(target)
        if target.is_dir() and not target.is_symlink():
            raise IsADirectoryError(errno.EISDIR, "a folder is in the way", str(target))
        folder = target.parent
        while not folder.exists() and not folder.is_symlink() and folder.parent != folder:
            folder = folder.parent
        if not folder.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, f"{folder} is a file, not a folder", str(target))


def commit(moves, aside: Path | None = None) -> None:
    """Move each staged file of ``moves`` (``(staged, target)`` pairs, on the targets' file
    system) into place: all of them or none. Every target is checked first (``check_targets``);
    a target that exists is linked aside (into the folder ``aside``, else beside its staged
    file) before it is replaced, and should a move fail (or a signal stop it) the files moved
    so far are taken out again, the old ones put back and the folders made for them removed,
    and the error names the target."""
    moves = [(Path(staged), Path(target)) for staged, target in moves]
    check_targets(target for _, target in moves)
    done, made = [], []
    try:
        for i, (staged, target) in enumerate(moves):
            with naming(target):
                made += make_folders(target.parent)
                old = None
                if os.path.lexists(target):
                    old = aside / str(i) if aside is not None else staged.with_name(staged.name + ".old")
                    _set_aside(target, old)
                done.append((target, old))
                os.replace(staged, target)
    except BaseException:
        for target, old in reversed(done):
            with contextlib.suppress(OSError):
                if old is None:
                    os.unlink(target)
                else:
                    os.replace(old, target)
        remove_folders(made)
        raise
    for _, old in done:
        if old is not None:
            with contextlib.suppress(OSError):
                os.unlink(old)


def _set_aside(target: Path, old: Path) -> None:
    """Keep ``target`` as ``old`` too: a hard link, so that ``target`` stays in place until it is
    replaced; moved there where the file system has no hard links."""
    try:
        os.link(target, old, follow_symlinks=False)
    except OSError:
        os.replace(target, old)


@contextlib.contextmanager
def staged_directory(target: str | os.PathLike, stale=(), inputs=()):
    """Yield a scratch folder; on success its files are moved into ``target`` (``commit``: all
    or none), and the files of ``stale`` (names relative to ``target``: a previous run's
    outputs) that this run did not write again are removed, so that the folder holds one run's
    outputs. ``inputs`` (``(what, path)`` pairs: the files the run reads) are never replaced or
    removed: InputError naming the file when one of them is among the outputs.

    If the block raises, the scratch folder is removed and ``target`` is left as it was; an
    OSError names the file in ``target`` rather than in the scratch folder.
    """
    from designer.errors import InputError

    from designer import interrupt

    target = Path(target)
    with interrupt.held():     # a signal here would leave the folders or the scratch folder behind
        made = make_folders(target.parent)
        with naming(target):
            try:
                scratch = Path(tempfile.mkdtemp(prefix=temp_prefix(target), dir=target.parent))
            except BaseException:
                remove_folders(made)
                raise
    done = False
    try:
        try:
            yield scratch
        except OSError as exc:
            _name_in(exc, scratch, target)
            raise
        names = sorted(item.relative_to(scratch) for item in scratch.rglob("*") if item.is_file())
        for name in names:
            for what, path in inputs:
                if same_file(target / name, path):
                    raise InputError(f"{target / name} is the {what} this command reads; write the "
                                     "outputs to another folder")
        # once begun, the outputs are moved in and the previous run's removed, whatever signal
        # comes meanwhile (it is raised after): the folder holds one whole run, old or new
        with interrupt.held():
            made += make_folders(target)
            commit([(scratch / name, target / name) for name in names],
                   aside=Path(tempfile.mkdtemp(prefix=".old.", dir=scratch)))
            done = True
            _remove_stale(target, stale, {name.as_posix() for name in names}, inputs)
            shutil.rmtree(scratch, ignore_errors=True)
            interrupt.wrote(target)
    finally:
        if not done:
            with interrupt.held():
                shutil.rmtree(scratch, ignore_errors=True)
                remove_folders(made)


def _remove_stale(target: Path, stale, written: set, inputs) -> None:
    """Remove the files of ``stale`` (a previous run's, relative to ``target``) that this run did
    not write again, except the run's inputs and names outside the folder itself."""
    for name in set(stale) - written:
        old = target / name
        if any(same_file(old, path) for _, path in inputs):
            continue
        if old.resolve().parent == target.resolve() and old.is_file():  # names in the folder itself
            with contextlib.suppress(OSError):
                old.unlink()


def _name_in(exc: OSError, scratch: Path, target: Path) -> None:
    """Make ``exc`` name the file in ``target`` where it names one in the scratch folder."""
    for attr in ("filename", "filename2"):
        value = getattr(exc, attr)
        if isinstance(value, (str, os.PathLike)):
            try:
                setattr(exc, attr, str(target / Path(value).relative_to(scratch)))
            except ValueError:
                pass


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
