"""Atomic file writing, and output folders that a run replaces whole but never wrongly.

A file is written to a temporary file in the same folder, then ``os.replace``: a failed run leaves
either the old file or none, never half a file.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_atomic(folder / "key.json", '{"ok": true}')
>>> (folder / "key.json").read_text()
'{"ok": true}'

An output folder is written in a work folder beside it (``.NAME.partial``, made exclusively, so it
is also the lock that keeps a second run out) and moved into place at the end, with a manifest,
``.grader-manifest.json``, that lists every file the run wrote and its SHA-256. A folder is only
replaced when it is new, empty, or (with ``force``) exactly what its manifest lists:

>>> with output_folder(folder / "out", command="doctest") as staging:
...     write_atomic(staging / "key.csv", "id\\n")
>>> sorted(p.name for p in (folder / "out").iterdir())
['.grader-manifest.json', 'key.csv']
>>> manifest_mismatches(folder / "out")
[]
>>> _ = (folder / "out" / "notes.txt").write_text("mine")
>>> manifest_mismatches(folder / "out")
['notes.txt (not written by grader)']
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
import signal
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any, BinaryIO

from grader.base.errors import GraderError, shown


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


UMASK = _umask()
"""The process umask, read once: temporary files are private until they take their final name."""


def usual_mode(path: Path, mode: int = 0o666) -> None:
    """Give a file made by ``tempfile`` the permissions ``mode`` less the umask, as ``open`` gives a new one
    (by default, those of any new file)."""
    os.chmod(path, mode & ~UMASK)


def write_atomic(path: Path, text: str | bytes | Iterable[str], mode: int = 0o666) -> None:
    """Write ``text`` (UTF-8), bytes, or text in pieces (written as they come) to ``path`` atomically, with
    the permissions ``mode`` less the umask. An ``OSError`` it raises names a path (a failed ``write()``, say
    on a full disk, names none by itself)."""
    with atomic_file(path, mode) as stream:
        if isinstance(text, (str, bytes)):
            stream.write(text.encode("utf-8") if isinstance(text, str) else text)
        else:
            for piece in text:
                stream.write(piece.encode("utf-8"))


@contextmanager
def atomic_file(path: Path, mode: int = 0o666) -> Iterator[BinaryIO]:
    """A binary stream to write ``path`` through, in as many pieces as it takes; ``path`` appears, with the
    permissions ``mode`` less the umask, only when the block ends without an error (two files written side by
    side, piece by piece, as ``generate`` writes a big key).

    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "key.csv"
    >>> with atomic_file(target) as stream:
    ...     _ = stream.write(b"id\\n")
    ...     target.exists()
    False
    >>> target.read_bytes()
    b'id\\n'
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as error:
        raise OSError(error.errno, error.strerror, str(path)) from None
    try:
        with os.fdopen(handle, "wb") as stream:
            yield stream
        usual_mode(Path(temporary), mode)
        os.replace(temporary, path)
    except BaseException as error:
        Path(temporary).unlink(missing_ok=True)
        if isinstance(error, OSError) and error.filename in (None, temporary):
            raise OSError(error.errno, error.strerror, str(path)) from None
        raise


_WHAT_TO_DO = {
    errno.ENOSPC: "free some space and run again",
    errno.EDQUOT: "free some space and run again",
    errno.EACCES: "choose a place you may write, or change its permissions",
    errno.EPERM: "choose a place you may write, or change its permissions",
    errno.EROFS: "choose a place on a writable disk",
    errno.ENAMETOOLONG: "choose a shorter name",
    errno.ENOTDIR: "a part of the path is a file, not a folder; check the path",
    errno.ENOENT: "check the path",
    errno.EISDIR: "give a file, not a folder",
}


def describe_os_error(error: OSError, outcome: str = "") -> str:
    """One line for a user: the path, the operating system's reason, the ``outcome``, what to do.

    >>> describe_os_error(OSError(errno.ENOSPC, "No space left on device", "hw7/key.json"), "hw7 is unchanged")
    'hw7/key.json: No space left on device; hw7 is unchanged; free some space and run again'
    """
    where = f"{error.filename} -> {error.filename2}" if error.filename2 else error.filename
    parts = [f"{where}: {error.strerror}" if where is not None else (error.strerror or str(error)), outcome,
             _WHAT_TO_DO.get(error.errno or 0, "")]
    return "; ".join(part for part in parts if part)


def shown_path(path: Path | str) -> str:
    r"""``path`` as text UTF-8 can write (in a report's cells): the bytes of a file name that are not
    UTF-8 (Python holds them as lone surrogates) shown as ``\xNN``.

    >>> shown_path(os.fsdecode(b"answers-\xff.csv"))
    'answers-\\xff.csv'
    """
    return os.fsencode(path).decode("utf-8", "backslashreplace")


MANIFEST = ".grader-manifest.json"
"""The file in every output folder that lists what the run wrote, each file with its SHA-256."""

_WORK = ".partial"
_NAME_MAX = 255


@contextmanager
def output_folder(out: Path, *, command: str, inputs: Sequence[Path] = (), force: bool = False) -> Iterator[Path]:
    """A staging folder to write into; on success it becomes ``out``, with a manifest of its files.

    Refused (:class:`GraderError`, before anything is written) when ``out`` is or contains one of
    ``inputs``, is the current or home folder (or holds one), goes through a file, has a name too long
    for the work folder, is being written by another run, or exists and is not empty, unless ``force``
    and it holds exactly what its manifest lists (nothing this tool did not write is ever deleted).
    On any failure the staging folder is removed and ``out`` is as it was.
    """
    target = _checked_target(out, inputs)
    created = _make_parents(out, target)
    try:
        work = _claim(out, target)
    except BaseException:
        _remove_empty(created)
        raise
    finished = False
    try:
        before = _state_before(out, target, force, command)
        staging = work / "new"
        staging.mkdir()
        try:
            yield staging
        except OSError as error:
            raise GraderError(describe_os_error(_outside(error, staging, out),
                                                f"nothing was written to {out}")) from None
        write_manifest(staging, command)
        with _signals_held():  # the previous output aside and the new one in: both renames, or neither
            _move_into_place(out, target, work, before)
            finished = True
    finally:
        _remove_work(out, work, finished)
        if not finished:
            _remove_empty(created)


@contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM wait (they are delivered at the end) where an interruption would leave no
    output in place; without ``pthread_sigmask`` (Windows) nothing is held."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def write_manifest(folder: Path, command: str) -> None:
    """List every file and folder under ``folder`` (the manifest aside) in ``folder/MANIFEST``."""
    files, folders, others = _listing(folder)
    if others:
        raise GraderError(f"{folder}: expected only files and folders to list in {MANIFEST}, got {others[0]}")
    document = {"schema": "grader-manifest", "version": 1, "command": command, "folders": sorted(folders),
                "files": {name: _sha256(path) for name, path in sorted(files.items())}}
    write_atomic(folder / MANIFEST, json.dumps(document, indent=1) + "\n")


def manifest_mismatches(folder: Path, named: Path | None = None) -> list[str]:
    """What in ``folder`` disagrees with its manifest: files and folders it does not list, and files
    changed since (a listed file that is gone is no mismatch: replacing the folder loses nothing).
    Messages name the folder as ``named`` (default ``folder``)."""
    manifest = _read_manifest(folder, named)
    files, folders, others = _listing(folder)
    found = [f"{name} (a link or special file, not written by grader)" for name in others]
    found += [f"{name}/ (a folder not made by grader)" for name in sorted(folders - set(manifest["folders"]))]
    for name, path in sorted(files.items()):
        if name not in manifest["files"]:
            found.append(f"{name} (not written by grader)")
        elif _sha256(path) != manifest["files"][name]:
            found.append(f"{name} (changed since grader wrote it)")
    return found


def _read_manifest(folder: Path, named: Path | None = None) -> dict[str, Any]:
    named = named or folder
    try:
        document = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise GraderError(f"{named}: exists and is not empty, and no grader run wrote it (there is no {MANIFEST}); "
                          "choose a new or empty --out: --force replaces only a folder a grader run wrote") from None
    except (OSError, ValueError, RecursionError) as error:
        raise GraderError(f"{named / MANIFEST}: expected a manifest grader wrote, got an unreadable file ({error}); "
                          "choose another --out") from None
    if not (isinstance(document, dict) and document.get("schema") == "grader-manifest"
            and isinstance(document.get("files"), dict) and isinstance(document.get("folders"), list)):
        raise GraderError(f"{named / MANIFEST}: expected a manifest grader wrote (schema grader-manifest), got "
                          "something else; choose another --out")
    return document


def _listing(folder: Path) -> tuple[dict[str, Path], set[str], list[str]]:
    """Regular files and folders under ``folder`` by relative name, and anything else (links, devices)."""
    files: dict[str, Path] = {}
    folders: set[str] = set()
    others: list[str] = []

    def fail(error: OSError) -> None:
        raise error

    for root, dirs, names in os.walk(folder, onerror=fail):
        base = Path(root)
        for name in dirs:
            relative = (base / name).relative_to(folder).as_posix()
            if (base / name).is_symlink():
                others.append(relative)
            else:
                folders.add(relative)
        for name in names:
            path = base / name
            relative = path.relative_to(folder).as_posix()
            if relative == MANIFEST:
                continue
            if path.is_symlink() or not path.is_file():
                others.append(relative)
            else:
                files[relative] = path
    return files, folders, sorted(others)


def _sha256(path: Path) -> str:
    with path.open("rb") as stream:
        return hashlib.file_digest(stream, "sha256").hexdigest()


def _checked_target(out: Path, inputs: Sequence[Path]) -> Path:
    """The output folder's real path, once it is known that replacing it cannot hurt."""
    absolute = Path(os.path.abspath(out))
    name_max = _name_max(absolute.parent)
    if len(os.fsencode(absolute.name)) + len(_WORK) + 1 > name_max:
        raise GraderError(f"{out}: expected a folder name of at most {name_max - len(_WORK) - 1} bytes (the run "
                          f"first writes it under a name {len(_WORK) + 1} bytes longer), got "
                          f"{len(os.fsencode(absolute.name))}; choose a shorter --out")
    if absolute.is_symlink():
        raise GraderError(f"{out}: is a symbolic link; give the folder it points to, or another --out")
    target = absolute.resolve()
    for ancestor in target.parents:
        if ancestor.exists():
            if not ancestor.is_dir():
                raise GraderError(f"{out}: expected a path through folders, but {ancestor} is a file; choose "
                                  "another --out")
            break
    for place, what in _places_to_keep():
        if target == place or target in place.parents:
            raise GraderError(f"{out}: is {what} or holds it, and --out is replaced whole; give a new folder "
                              "of its own, such as hw7")
    for source in inputs:
        if _holds(absolute, target, source):
            raise GraderError(f"{out}: is or holds the input {source}, and --out is replaced whole; choose an "
                              "--out that holds none of the inputs")
    return target


def _holds(absolute: Path, target: Path, source: Path) -> bool:
    """Whether the folder (``absolute``, whose real path is ``target``) is or holds ``source``: by its
    path, or, where paths are spelt differently (a case-insensitive disk's ``HW/key.json`` in ``hw``, a
    folder mounted twice), by being the same folder as one of the source's."""
    candidates = {Path(os.path.abspath(source)), source.resolve()}
    if any(folder == candidate or folder in candidate.parents for folder in (absolute, target)
           for candidate in candidates):
        return True
    try:
        folder = os.stat(target)
    except OSError:  # nothing there yet: nothing to replace
        return False
    for candidate in candidates:
        for place in (candidate, *candidate.parents):
            with suppress(OSError):
                if os.path.samestat(os.stat(place), folder):
                    return True
    return False


def _name_max(folder: Path) -> int:
    for existing in (folder, *folder.parents):
        with suppress(OSError):
            if existing.is_dir():
                return os.pathconf(existing, "PC_NAME_MAX")
    return _NAME_MAX


def _places_to_keep() -> list[tuple[Path, str]]:
    places = []
    with suppress(OSError):
        places.append((Path.cwd().resolve(), "the current folder"))
    with suppress(OSError, RuntimeError, KeyError):
        places.append((Path.home().resolve(), "your home folder"))
    return places


def _make_parents(out: Path, target: Path) -> list[Path]:
    """Create the folders above ``target``; returns those created, deepest first."""
    missing = [folder for folder in (target.parent, *target.parent.parents) if not folder.exists()]
    try:
        if missing:
            target.parent.mkdir(parents=True)
    except OSError as error:
        _remove_empty(missing)
        raise GraderError(f"{out}: cannot create its folder ({describe_os_error(error)})") from None
    return missing


def _remove_empty(folders: Sequence[Path]) -> None:
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


def _claim(out: Path, target: Path) -> Path:
    """Make the work folder beside ``target``; it exists only while one run writes there."""
    work = target.parent / f".{target.name}{_WORK}"
    try:
        work.mkdir()
    except FileExistsError:
        shown = out.parent / work.name
        raise GraderError(f"{out}: another grader run is writing it (its work folder {shown} exists); wait for "
                          f"that run to finish or, if none is running (one was stopped), delete {shown}") from None
    except OSError as error:
        raise GraderError(f"{out}: cannot write in {out.parent} ({error.strerror}); choose an --out in a "
                          "folder you may write") from None
    return work


def _state_before(out: Path, target: Path, force: bool, command: str) -> object:
    """What ``target`` holds now: nothing (None), an empty folder ("empty"), or the output of an earlier run of
    ``command`` (its manifest). Another command's output is never replaced: ``grader grade --force`` on the
    folder ``grader demo`` wrote would delete its key, sheets and submissions."""
    if not os.path.lexists(target):
        return None
    if target.is_symlink() or not target.is_dir():
        raise GraderError(f"{out}: exists and is not a folder; choose another --out")
    if not any(target.iterdir()):
        return "empty"
    if not force:
        raise GraderError(f"{out}: the output folder exists and is not empty; choose another --out, or --force to "
                          f"replace it (only if a grader run wrote it, as its {MANIFEST} says)")
    manifest = _read_manifest(target, out)
    writer = manifest.get("command")
    if writer != command:
        name = writer if isinstance(writer, str) and writer.isprintable() and len(writer) <= 60 else shown(writer)
        raise GraderError(f"{out}: written by {name} (as its {MANIFEST} says); {command} --force replaces only "
                          f"a folder {command} wrote, never another command's files; choose another --out")
    mismatches = manifest_mismatches(target, out)
    if mismatches:
        listed = ", ".join(mismatches[:5]) + (f" and {len(mismatches) - 5} more" if len(mismatches) > 5 else "")
        raise GraderError(f"{out}: --force replaces only a folder that holds exactly what its {MANIFEST} lists, "
                          f"got {listed}; move those out of it, or choose another --out")
    return manifest


def _move_into_place(out: Path, target: Path, work: Path, before: object) -> None:
    """``work/new`` becomes ``target``, if ``target`` is still as it was when the run began."""
    gone = "this run wrote nothing; choose another --out"
    if before is None and os.path.lexists(target):
        raise GraderError(f"{out}: appeared while this run was writing it (another program made it); it is left "
                          f"as it is and {gone}")
    if before == "empty" and (not target.is_dir() or any(target.iterdir())):
        raise GraderError(f"{out}: was filled while this run was writing it; it is left as it is and {gone}")
    if isinstance(before, dict) and (manifest_mismatches(target, out) or _read_manifest(target, out) != before):
        raise GraderError(f"{out}: changed while this run was writing it; it is left as it is and {gone}")
    if isinstance(before, dict):
        _rename(target, work / "old", out, "move the previous output aside")
        try:
            _rename(work / "new", target, out, "move the new output into place")
        except GraderError:
            os.replace(work / "old", target)
            raise
    else:
        # rename() onto a folder replaces it only when it is empty, so nothing that appeared is lost.
        _rename(work / "new", target, out, "move the new output into place")


def _rename(source: Path, destination: Path, out: Path, doing: str) -> None:
    try:
        os.rename(source, destination)
    except OSError as error:
        raise GraderError(f"{out}: cannot {doing} ({error.strerror}); the previous output is unchanged and this "
                          "run wrote nothing; choose another --out") from None


def _remove_work(out: Path, work: Path, finished: bool) -> None:
    if (work / "old").exists() and not finished:
        # The previous output could not be put back: never delete it.
        raise GraderError(f"{out}: the previous output could not be put back; it is in {work / 'old'}")
    try:
        shutil.rmtree(work)
    except FileNotFoundError:
        pass
    except OSError as error:
        if finished:
            raise GraderError(f"{out}: written, but its work folder {work} could not be removed "
                              f"({error.strerror}); delete it") from None


def _outside(error: OSError, staging: Path, out: Path) -> OSError:
    """The error with a path inside the staging folder shown as the output path it stands for."""
    if error.filename is None:
        return OSError(error.errno, error.strerror, str(out))
    try:
        inside = Path(error.filename).relative_to(staging)
    except ValueError:
        return error
    return OSError(error.errno, error.strerror, str(out / inside))
