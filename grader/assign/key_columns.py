"""``key.columns.npz``: the students of ``key.json`` in columns, a cache grading reads instead of the JSON.

``key.json`` stays the key: readable, documented, what a person edits or checks. Beside it ``grader
generate`` writes this sidecar, which holds the same students as arrays (each answer's value, points, and an
index into one table of the texts and tolerances the class shares), with the SHA-256 of the ``key.json``
bytes it was made from. Grading (:func:`grader.grade.key.load_key`) uses it only when that hash is the
hash of the ``key.json`` it was given; a sidecar that is missing, made from another ``key.json`` (the key
edited, or copied without it), or unreadable is passed over and ``key.json`` is read, so it never changes a
result: at worst grading takes as long as it did without it.

The format is numpy's (a zip of ``.npy`` arrays, read with ``allow_pickle=False``: opening it runs no
code), written with fixed zip dates, so that generating twice gives byte-identical files; ``meta`` is
UTF-8 JSON: the key without its students, the tables, and the students' texts.

A student shaped otherwise than ``grader generate`` writes them (a value that is no number, text or null,
a parameter that is no number, an unusual key) makes no sidecar: grading then reads ``key.json`` alone.

>>> import json, pathlib, tempfile
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = (folder / "key.json").write_text(json.dumps({"schema": "grader-key", "version": 2, "students": [
...     {"id": "007", "name": "Ana", "email": "a@x", "section": "1", "problems": [{"key": "1",
...      "params": {"h": 2.5}, "answers": {"e": {"value": 0.7, "unit": "", "label": "1a", "points": 2,
...                                             "tolerance": {"mode": "rtol", "rtol": 0.01, "atol": 0}}}}]}]}))
>>> write_key_columns(folder / "key.json")
True
>>> columns = read_key_columns(folder / "key.json")
>>> columns.ids, columns.value.tolist(), columns.texts[columns.code[0][LABEL]], columns.params.tolist()
(['007'], [0.7], '1a', [2.5])
>>> _ = (folder / "key.json").write_text("another key")
>>> read_key_columns(folder / "key.json") is None  # made from another key.json: not used
True
"""

from __future__ import annotations

import hashlib
import io
import itertools
import json
import os
import re
import stat
import sys
import zipfile
from array import array
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from grader.base.errors import GraderError
from grader.base.files import write_atomic
from grader.base.inputs import decode_text

FORMAT, VERSION = "grader-key-columns", 1
SUFFIX = ".columns.npz"  # key.json -> key.columns.npz
TEXT, UNIT, LABEL, TOLERANCE, UNDEFINED = range(5)  # the columns of ``code``, each an index or NUMBER/NONE
NUMBER, NONE = -1, -2  # ``code[TEXT]``: the value is the number in ``value``, or null (``code[UNDEFINED]``: none)
_ARRAYS = ("meta", "shape", "value", "points", "code", "params")
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # the zip format's earliest: no date of the run in the file
_ESCAPED_SURROGATE = re.compile(r"\\u[dD][89a-fA-F]")  # half a character: key.json's reader refuses it itself


def sidecar(key: Path) -> Path:
    """Where the columns of ``key`` are (``hw/key.json`` -> ``hw/key.columns.npz``)."""
    return key.with_name(key.stem + SUFFIX)


@dataclass(frozen=True)
class KeyColumns:
    """A key's students in columns. Per student (in the key's order): id, name, email, section, own due
    time (None: none) and shape (an index into ``shapes``); a shape is the student's problems in order, each
    its key, its answers' names and its parameters' names. Per answer of every student, in that order:
    ``value`` (the number, NaN where it is no number), ``points`` and ``code`` (TEXT, UNIT, LABEL,
    TOLERANCE, UNDEFINED: indices into ``texts`` or ``tolerances``). Per parameter of every student,
    in order: ``params``."""

    header: dict[str, Any]  # key.json without its students
    ids: list[str]
    names: list[str]
    emails: list[str]
    sections: list[str]
    dues: list[str | None]
    shapes: list[list[tuple[str, list[str], list[str]]]]
    texts: list[str]
    tolerances: list[dict[str, Any]]
    shape: np.ndarray
    value: np.ndarray
    points: np.ndarray
    code: np.ndarray
    params: np.ndarray


class _UnusualKeyError(Exception):
    """A student not shaped as grader generate writes them: no sidecar."""


def write_key_columns(key: Path) -> bool:
    """Write the sidecar of the key file ``key`` from its bytes on disk; returns whether one was written
    (a key not as grader generate writes keys gets none, and an old sidecar of it is removed). A key laid out
    as :func:`grader.assign.keyfile.key_json` lays it out is read a line, a student, at a time (a big
    class's key is never held whole); any other is decoded whole."""
    try:
        try:
            with open(key, "rb") as stream:
                digest = hashlib.sha256()
                header, students = _by_line(stream, digest)
                payload = _columns(header, students, digest)
        except _LayoutError:
            data = key.read_bytes()
            text = decode_text(data, key)
            if _ESCAPED_SURROGATE.search(text):
                raise _UnusualKeyError from None
            raw = json.loads(text, parse_constant=_no_constant)
            if type(raw) is not dict or type(raw.get("students")) is not list:
                raise _UnusualKeyError from None
            payload = _columns(raw, raw["students"], hashlib.sha256(data))
    except (GraderError, ValueError, RecursionError, _UnusualKeyError):
        sidecar(key).unlink(missing_ok=True)
        return False
    write_atomic(sidecar(key), payload)
    return True


class _LayoutError(Exception):
    """The key is not laid out a student a line: it is decoded whole."""


_STUDENTS = b' "students": [\n'


def _by_line(stream: BinaryIO, digest: Any) -> tuple[dict[str, Any], Iterator[Any]]:
    """The header of a key laid out by ``key_json`` and its students, decoded one line at a time as they
    are iterated; ``digest`` takes every byte read. :class:`_LayoutError` where the layout differs."""
    lines = _hashed(stream, digest)
    head = list(itertools.takewhile(lambda line: line != _STUDENTS, lines))
    text = _decoded(b"".join(head)).rstrip()
    if not text.startswith("{") or not text.endswith(","):
        raise _LayoutError
    header = _loaded(text[:-1] + "}")
    if type(header) is not dict:
        raise _LayoutError
    return header, _students(lines)


def _students(lines: Iterator[bytes]) -> Iterator[Any]:
    """The students of the lines after ``"students": [``, each line one (a comma after all but the last),
    then `` ]`` and ``}`` and the end of the file."""
    last = None  # the last student's line
    for line in lines:
        text = _decoded(line).strip()
        if text == "]":
            break
        if (last is not None and not last.endswith(",")) or not text.startswith("{"):
            raise _LayoutError
        last = text
        yield _loaded(text.removesuffix(","))
    else:
        raise _LayoutError
    if (last is not None and last.endswith(",")) or _decoded(b"".join(lines)).strip() != "}":
        raise _LayoutError


def _hashed(stream: BinaryIO, digest: Any) -> Iterator[bytes]:
    for line in stream:
        digest.update(line)
        yield line


def _decoded(data: bytes) -> str:
    """UTF-8 without a byte-order mark, NUL or half a character escaped: else the whole file is decoded, as
    grading decodes it."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise _LayoutError from None
    if text.startswith("\ufeff") or "\0" in text or _ESCAPED_SURROGATE.search(text):
        raise _LayoutError
    return text


def _loaded(text: str) -> Any:
    try:
        return json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError):
        raise _LayoutError from None


def read_key_columns(key: Path) -> KeyColumns | None:
    """The sidecar of ``key`` if there is one made from the bytes ``key`` holds now and it reads whole; else
    None (grading reads ``key.json``). Neither file is held whole: the sidecar's arrays are read from the file,
    and ``key.json`` is hashed a piece at a time, only once the sidecar has been found sound (a key of a
    million students is 3.4 GB)."""
    try:
        with open(sidecar(key), "rb") as stream:
            status = os.fstat(stream.fileno())
            size = _size(key)
            # The columns are smaller than the JSON they come from: a bigger file is no sidecar of it.
            if size is None or not stat.S_ISREG(status.st_mode) or status.st_size > _most(size) \
                    or not _stored_whole(stream, status.st_size):
                return None
            stream.seek(0)
            with np.load(stream, allow_pickle=False) as archive:
                if sorted(archive.files) != sorted(_ARRAYS):
                    return None
                meta = json.loads(archive["meta"].tobytes().decode("utf-8"))
                if not (isinstance(meta, dict) and meta.get("format") == FORMAT and meta.get("version") == VERSION
                        and meta.get("key_sha256") == _sha256(key, size)):
                    return None
                arrays = {name: archive[name] for name in _ARRAYS[1:]}
        return _checked(meta, arrays)
    except (OSError, ValueError, KeyError, TypeError, EOFError, MemoryError, zipfile.BadZipFile):
        return None  # a sidecar cut short, altered, or of another layout: key.json is read instead


def _size(key: Path) -> int | None:
    """The size of ``key``, a regular file (None: another kind of file, which has no sidecar: a pipe read to
    hash it would be read no more)."""
    status = key.stat()
    return status.st_size if stat.S_ISREG(status.st_mode) else None


def _sha256(key: Path, size: int) -> str | None:
    """The SHA-256 of ``key``'s bytes, read a MiB at a time; None if it holds more than ``size`` (written to
    while it was read: its sidecar is not used)."""
    digest, read = hashlib.sha256(), 0
    with open(key, "rb") as stream:
        while piece := stream.read(1 << 20):
            read += len(piece)
            if read > size:
                return None
            digest.update(piece)
    return digest.hexdigest()


def _most(size: int) -> int:
    """The largest sidecar of a key of ``size`` bytes (the zip's own entries aside, its columns take at most the
    JSON's length)."""
    return size + (1 << 16)


def _stored_whole(stream: BinaryIO, size: int) -> bool:
    """Whether the zip of ``size`` bytes holds its arrays as they are (no compression: no member unpacks to more
    than the file)."""
    try:
        with zipfile.ZipFile(stream) as archive:
            return all(entry.compress_type == zipfile.ZIP_STORED and entry.file_size <= size
                       for entry in archive.infolist())
    except (zipfile.BadZipFile, ValueError, EOFError, OSError):
        return False


def _checked(meta: dict[str, Any], arrays: Mapping[str, np.ndarray]) -> KeyColumns | None:
    """The columns, if their lengths and indices agree with each other (a sidecar altered in place whose
    zip still reads is passed over too)."""
    columns = KeyColumns(meta["header"], meta["ids"], meta["names"], meta["emails"], meta["sections"], meta["dues"],
                         [[(key, list(answers), list(params)) for key, answers, params in shape]
                          for shape in meta["shapes"]], meta["texts"], meta["tolerances"], **arrays)
    students = len(columns.ids)
    if not all(len(entries) == students for entries in (columns.names, columns.emails, columns.sections,
                                                          columns.dues, columns.shape)):
        return None
    if columns.shape.dtype != np.int32 or columns.code.dtype != np.int32 or columns.value.dtype != np.float64 \
            or columns.points.dtype != np.float64 or columns.params.dtype != np.float64:
        return None
    if students and not 0 <= int(columns.shape.min()) <= int(columns.shape.max()) < len(columns.shapes):
        return None
    counts = np.array([sum(len(names) for _, names, _ in shape) for shape in columns.shapes] or [0])
    params = np.array([sum(len(names) for _, _, names in shape) for shape in columns.shapes] or [0])
    answers = (int(counts[columns.shape].sum()),)
    if columns.code.shape != (*answers, 5) or columns.value.shape != answers or columns.points.shape != answers \
            or columns.params.shape != (int(params[columns.shape].sum()),):
        return None
    code, texts = columns.code, len(columns.texts)
    if code.size and not (code[:, [UNIT, LABEL]].min() >= 0 and code[:, [UNIT, LABEL]].max() < texts
                          and code[:, [TEXT, UNDEFINED]].min() >= NONE and code[:, [TEXT, UNDEFINED]].max() < texts
                          and code[:, TOLERANCE].min() >= 0 and code[:, TOLERANCE].max() < len(columns.tolerances)):
        return None
    return columns


def _columns(header: Mapping[str, Any], students: Iterable[Any], digest: Any) -> bytes:
    """The sidecar's bytes for the key's ``header`` (its entries; ``students`` among them is left out) and
    its ``students``, decoded; ``digest``, of the file's bytes, is read once every student is. Raises
    :class:`_UnusualKeyError` where a student is not shaped as grader generate writes them."""
    texts: dict[str, int] = {}
    tolerances: dict[Any, tuple[dict[str, Any], int]] = {}
    shapes: dict[tuple[Any, ...], int] = {}
    people: dict[str, list[Any]] = {"ids": [], "names": [], "emails": [], "sections": [], "dues": []}
    # Typed arrays, not lists of Python numbers: a million students have five million answers.
    shape, value, points, code, params = array("i"), array("d"), array("d"), array("i"), array("d")
    for student in students:
        if type(student) is not dict:
            raise _UnusualKeyError
        for entry, field in (("ids", "id"), ("names", "name"), ("emails", "email"), ("sections", "section")):
            people[entry].append(_string(student.get(field, "") if field != "id" else student.get("id")))
        due = student.get("due")
        people["dues"].append(None if due is None else _string(due))
        problems = student.get("problems")
        if type(problems) is not list:
            raise _UnusualKeyError
        layout = []
        for problem in problems:
            answers, printed = _object(_object(problem).get("answers")), problem.get("params", {})
            if type(problem.get("key")) is not str or type(printed) is not dict:
                raise _UnusualKeyError
            layout.append((problem["key"], list(answers), list(printed)))
            for answer in answers.values():
                number, text = _value(_object(answer))
                value.append(number)
                points.append(_number(answer.get("points")))
                tolerance = _object(answer.get("tolerance"))
                undefined = answer.get("undefined")
                code.extend((NUMBER if text is None and answer["value"] is not None else
                             NONE if text is None else _index(texts, text),
                             _index(texts, _string(answer.get("unit", ""))),
                             _index(texts, _string(answer.get("label"))),
                             _tolerance(tolerances, tolerance),
                             NONE if undefined is None else _index(texts, _string(undefined))))
            params.extend(_number(number) for number in printed.values())
        shape.append(shapes.setdefault(tuple((key, tuple(answers), tuple(printed)) for key, answers, printed in layout),
                                       len(shapes)))
    meta = {"format": FORMAT, "version": VERSION, "key_sha256": digest.hexdigest(),
            "header": {name: entry for name, entry in header.items() if name != "students"}, **people,
            "shapes": list(shapes), "texts": list(texts), "tolerances": [entry for entry, _ in tolerances.values()]}
    return _npz({"meta": np.frombuffer(json.dumps(meta, ensure_ascii=False).encode("utf-8"), np.uint8),
                 "shape": np.frombuffer(shape, np.int32), "value": np.frombuffer(value, np.float64),
                 "points": np.frombuffer(points, np.float64), "code": np.frombuffer(code, np.int32).reshape(-1, 5),
                 "params": np.frombuffer(params, np.float64)})


def _npz(arrays: Mapping[str, np.ndarray]) -> bytes:
    """``numpy.savez`` with fixed dates (its own stamps the time of the run)."""
    stream = io.BytesIO()
    with zipfile.ZipFile(stream, "w", zipfile.ZIP_STORED) as archive:
        for name, array in arrays.items():
            with archive.open(zipfile.ZipInfo(f"{name}.npy", _ZIP_DATE), "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.ascontiguousarray(array), allow_pickle=False)
    return stream.getvalue()


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is no number a key holds")


def _tolerance(table: dict[Any, tuple[dict[str, Any], int]], tolerance: dict[str, Any]) -> int:
    """The tolerance's index in ``table``, by value (``True`` is not ``1``: the types are part of it)."""
    try:
        key: Any = (tuple(tolerance.items()), tuple(map(type, tolerance.values())))
        hash(key)
    except TypeError:  # a list or an object among the values: by its text
        key = json.dumps(tolerance, ensure_ascii=False)
    return table.setdefault(key, (tolerance, len(table)))[1]


def _index(table: dict[str, int], text: str) -> int:
    return table.setdefault(text, len(table))


def _string(value: Any) -> str:
    if type(value) is not str:
        raise _UnusualKeyError
    return value


def _object(value: Any) -> dict[str, Any]:
    if type(value) is not dict:
        raise _UnusualKeyError
    return value


def _number(value: Any) -> float:
    """A number of the key as grading reads it (``float``); a bool, or an integer beyond float64, is unusual."""
    if type(value) not in (int, float) or abs(value) > sys.float_info.max:
        raise _UnusualKeyError
    try:
        return float(value)
    except OverflowError:
        raise _UnusualKeyError from None


def _value(answer: Mapping[str, Any]) -> tuple[float, str | None]:
    """An answer's value: its number (NaN: none) and its text (an expression; None: a number or null)."""
    if "value" not in answer:
        raise _UnusualKeyError
    value = answer["value"]
    if value is None:
        return float("nan"), None
    if type(value) is str:
        return float("nan"), value
    return _number(value), None


