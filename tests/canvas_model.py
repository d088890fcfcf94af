"""Canvas' gradebook export and import, modelled from the canvas-lms source for the tests of ``canvas.csv``
(never from grader's code): a course of students and assignments, the CSV Canvas' exporter writes of it,
and what Canvas' importer and upload page then do with a file.

The source read (github.com/instructure/canvas-lms):

- ``lib/gradebook_exporter.rb`` (commit 0140a2ef), ``csv_data``: the header ``["LastName", "FirstName"]``
  or ``["Student"]``, then ``"ID"``, ``"SIS User ID" if include_sis_id``, ``"SIS Login ID"``,
  ``"Integration ID" if include_sis_id && show_integration_id?``, ``"Root Account" if include_sis_id &&
  include_root_account``, ``"Section"``, then ``assignments.map(&:title_with_id)`` (``"#{title} (#{id})"``);
  a posting row when ``assignments.any? { |assignment| show_as_hidden?(assignment) }``, whose cell is
  ``"Manual Posting"``, or ``"%{manual_posting} (scores hidden from instructors)"`` when
  ``assignment.unposted_anonymous_submissions?``; the row ``["    Points Possible", nil, nil, nil]`` with
  ``format_numbers(a.points_possible)``; a student's cell ``"EX"`` if ``submission.try(:excused?)``, else
  ``format_numbers(submission.try(:score))``, and ``"N/A"`` unless ``visible_assignments[a.id].include?
  (student.id) && !a.unposted_anonymous_submissions?``; ``format_numbers`` is ``I18n.n(number,
  precision: 2)`` (``17,50`` in a decimal-comma locale, whose exports use ``;``); ``student_name``
  writes a name that matches ``/^\\s*=/`` as ``="name"``.
- ``lib/gradebook_importer.rb`` (commit 00b222d7): ``csv_stream`` (``converters: %i[nil
  decimal_comma_to_period]``, ``skip_lines: /^[;, ]+$/``, ``col_sep`` from ``identify_delimiter`` of the
  first 3 lines); ``row_has_student_headers?`` (``row[0].include?("Student") && row[1].include?("ID")``, or
  ``LastName``, ``FirstName``, ``ID``) and ``update_column_count`` (``@has_student_first_last_names =
  (row[0] == "LastName" && row[1] == "FirstName")``, the SIS columns by position, ``last_student_info_column
  (row).include?("Section")``); ``parse_assignments`` (``Assignment.title_and_id(name_and_id)``, ``/\\A(.*)
  \\s\\((\\d+)\\)\\z/``, then ``@all_assignments[id.to_i]``, then ``a.title == name_and_id`` among
  ``@context.assignments.published``, else ``Assignment.new``); ``check_for_non_student_row`` (``row[0]&.
  include?("Points Possible")``, and a row whose every cell is ``/^\\s*(Muted|Manual Posting.*)?\\s*$/i``);
  ``process_student`` (``@all_students[student_id.to_i]``, then ``@pseudonyms_by_sis_id[sis_user_id]``,
  then ``@pseudonyms_by_login_id[sis_login_id]``, exact hash keys, then ``s.name == name ||
  s.sortable_name == name``); ``process_submissions`` (``grade = row[assignment_index]&.strip``, ``""``
  unless ``assignment_assigned_to_student``); ``gradeable?`` (``false if
  assignment&.unposted_anonymous_submissions?``); ``process_pp`` (``assignment.points_possible =
  row[...]``); ``no_change_to_value?`` (equal, or both blank, or equal at ``precision: 2``).
- ``ui/features/gradebook_uploads/jquery/process_gradebook_upload.js``, ``populateGradeDataPerSubmission``:
  ``if (submission.original_grade === submission.grade) return // no change``, ``EX`` becomes ``{excuse:
  true}``, anything else ``{posted_grade: submission.grade}`` (so an empty cell removes a grade).
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field


@dataclass
class Student:
    """A Canvas user in the course: ``grade`` is their current score (a float), ``"EX"`` or None."""

    canvas_id: int
    name: str
    sortable_name: str
    sis_user_id: str | None
    login: str
    section: str = "Section 1"
    grade: float | str | None = None
    assigned: bool = True
    integration_id: str = ""


@dataclass
class Assignment:
    canvas_id: int
    title: str
    points: float
    published: bool = True
    posting: str = ""  # "", "Manual Posting" or "Manual Posting (scores hidden from instructors)"


@dataclass
class Course:
    students: list[Student]
    assignments: list[Assignment]


@dataclass
class Layout:
    """How the exporter is set: names as LastName/FirstName, SIS columns, integration ids, root account,
    and the locale's separators (``;`` and a decimal comma)."""

    first_last: bool = False
    include_sis_id: bool = True
    integration_id: bool = False
    root_account: bool = False
    decimal_comma: bool = False


def export(course: Course, layout: Layout) -> str:
    """The CSV ``GradebookExporter#csv_data`` writes of ``course`` (without its totals columns)."""
    header = ["LastName", "FirstName"] if layout.first_last else ["Student"]
    header.append("ID")
    header += ["SIS User ID"] if layout.include_sis_id else []
    header.append("SIS Login ID")
    header += ["Integration ID"] if layout.include_sis_id and layout.integration_id else []
    header += ["Root Account"] if layout.include_sis_id and layout.root_account else []
    header.append("Section")
    rows = [header + [f"{a.title} ({a.canvas_id})" for a in course.assignments]]
    identity = len(header)
    if any(a.posting for a in course.assignments):
        rows.append([""] * identity + [a.posting for a in course.assignments])
    points = [_number(a.points, layout) for a in course.assignments]
    rows.append(["    Points Possible"] + [""] * (identity - 1) + points)
    for student in course.students:
        surname, _, given = student.sortable_name.partition(", ")
        row = [_name(surname), _name(given)] if layout.first_last else [_name(student.sortable_name)]
        row.append(str(student.canvas_id))
        row += [student.sis_user_id or ""] if layout.include_sis_id else []
        row.append(student.login)
        row += [student.integration_id] if layout.include_sis_id and layout.integration_id else []
        row += ["uni.instructure.com"] if layout.include_sis_id and layout.root_account else []
        row.append(student.section)
        for a in course.assignments:
            hidden = a.posting.startswith("Manual Posting (")
            row.append("N/A" if not student.assigned or hidden else "EX" if student.grade == "EX"
                       else _number(student.grade, layout))
        rows.append(row)
    stream = io.StringIO()
    csv.writer(stream, delimiter=";" if layout.decimal_comma else ",", lineterminator="\n").writerows(rows)
    return stream.getvalue()


def _number(value: float | str | None, layout: Layout) -> str:
    if value is None:
        return ""
    text = f"{float(value):.2f}"
    return text.replace(".", ",") if layout.decimal_comma else text


def _name(name: str) -> str:
    return f'="{name}"' if re.match(r"\s*=", name) else name


@dataclass
class Imported:
    """What an upload of a file does: the assignment updated (its Canvas id) or created (its title), the
    grades posted by Canvas user id (``"EX"`` for an excuse, ``""`` for a grade removed), whether the
    assignment's points changed, and the rows no course student matched (Canvas offers to create them)."""

    assignment: int | str
    posted: dict[int, str] = field(default_factory=dict)
    points_changed: bool = False
    unknown: list[str] = field(default_factory=list)


class InvalidHeaderRow(Exception):  # noqa: N818 (Canvas' name)
    """``GradebookImporter::InvalidHeaderRow``: the upload fails with "Invalid header row"."""


def import_file(text: str, course: Course, first_last_allowed: bool = True) -> Imported:
    """Canvas' import of the file ``text`` (the one assignment column grader writes) into ``course``."""
    rows = _parse(text)
    header = rows[0]
    student_columns, sis_column, login_column = _columns(header, first_last_allowed)
    first_last = header[0] == "LastName" and header[1] == "FirstName"
    title = header[student_columns]
    assignment = _assignment(title, course)
    result = Imported(assignment.canvas_id if assignment else title)
    for row in rows[1:]:
        if "Points Possible" in row[0]:
            if assignment and row[student_columns] and float(row[student_columns]) != assignment.points:
                result.points_changed = True
            continue
        if all(re.fullmatch(r"\s*(Muted|Manual Posting.*)?\s*", cell, re.I) for cell in row):
            continue
        student = _student(row, course, sis_column, login_column, first_last)
        if student is None:
            result.unknown.append(row[0])
            continue
        grade = row[student_columns].strip()
        if assignment is not None and not student.assigned:
            grade = ""
        original = "" if assignment is None else "EX" if student.grade == "EX" else \
            "" if student.grade is None else f"{float(student.grade):.2f}"
        if assignment is not None and assignment.posting.startswith("Manual Posting ("):
            continue  # gradeable? is false: Canvas refuses ("prevented_grading_ungradeable_submission")
        if not _no_change(grade, original):
            result.posted[student.canvas_id] = "EX" if grade.upper() in ("EX", "EXCUSED") else grade
    return result


def _parse(text: str) -> list[list[str]]:
    """``csv_stream``: the delimiter of the first 3 lines, blank-ish lines skipped, numbers' decimal commas
    made points (``decimal_comma_to_period``)."""
    lines = text.splitlines()
    counts = {}
    for separator in ";,":
        sizes = {len(next(csv.reader([line], delimiter=separator))) for line in lines[:3]}
        counts[separator] = sizes.pop() if len(sizes) == 1 else 0
    delimiter = ";" if counts[";"] > counts[","] else ","
    kept = [line for line in lines if not re.fullmatch(r"[;, ]+", line)]
    return [[_decimal_comma_to_period(cell) for cell in row] for row in csv.reader(kept, delimiter=delimiter)]


def _decimal_comma_to_period(cell: str) -> str:
    if not re.fullmatch(r"-?[0-9.,]+%?", cell):
        return cell
    *whole, last = re.split(r"[,.]", cell)
    return f"{''.join(whole)}.{last}" if whole else last


def _columns(header: list[str], first_last_allowed: bool) -> tuple[int, int | None, int | None]:
    """``header?`` and ``update_column_count``: how many student columns, and where the SIS columns are."""
    has_headers = ((len(header) > 3 and "Student" in header[0] and "ID" in header[1])
                   or (len(header) > 4 and "LastName" in header[0] and "FirstName" in header[1] and "ID" in header[2]))
    if not has_headers:
        raise InvalidHeaderRow(header[:3])
    first_last = header[0] == "LastName" and header[1] == "FirstName"
    if first_last and not first_last_allowed:
        raise InvalidHeaderRow(header[:3])
    columns = names = 4 if first_last else 3
    sis = login = None
    if re.search(r"SIS\s+Login\s+ID", header[names - 1]):
        login, columns = names - 1, columns + 1
    elif re.search(r"SIS\s+User\s+ID", header[names - 1]) and re.search(r"SIS\s+Login\s+ID", header[names]):
        integration = 1 if re.search(r"Integration\s+ID", header[names + 1]) else 0
        sis, login, columns = names - 1, names, columns + 2 + integration
        if re.search(r"Root\s+Account", header[names + 1 + integration]):
            columns += 1
    if "Section" not in header[columns - 1]:
        raise InvalidHeaderRow(header[:columns])
    return columns, sis, login


def _assignment(header: str, course: Course) -> Assignment | None:
    """``parse_assignments``: by the id of ``Title (id)``, else by the exact title, among published
    assignments; None for a new one."""
    published = [a for a in course.assignments if a.published]
    match = re.fullmatch(r"(.*)\s\((\d+)\)", header, re.S)
    found = [a for a in published if match and a.canvas_id == int(match[2])]
    return (found or [a for a in published if a.title == header] or [None])[0]


def _student(row: list[str], course: Course, sis: int | None, login: int | None, first_last: bool) -> Student | None:
    """``process_student``: ID, then SIS User ID, then SIS Login ID (exact), then name or sortable name."""
    student_id = row[2] if first_last else row[1]
    found = [s for s in course.students if student_id.strip().isdigit() and s.canvas_id == int(student_id)]
    if not found and sis is not None and row[sis]:
        found = [s for s in course.students if s.sis_user_id == row[sis]]
    if not found and login is not None and row[login]:
        found = [s for s in course.students if s.login == row[login]]
    if not found:
        name = f"{row[1]} {row[0]}".strip() if first_last else row[0]
        found = [s for s in course.students if name in (s.name, s.sortable_name)]
    return found[0] if found else None


def _no_change(new: str, current: str) -> bool:
    """``no_change_to_value?`` with ``consider_excused``."""
    if new == current or (new in ("", "-") and current in ("", "-")):
        return True
    if not new or not current or "EX" in (new.upper(), current.upper()):
        return False
    try:
        return f"{float(new):.2f}" == f"{float(current):.2f}"
    except ValueError:
        return False
