"""CSV pieces: the text of a file written as it comes is the text of the whole, whatever the piece size."""

from __future__ import annotations

import csv
import io

import pytest

from grader.base.spreadsheet import csv_pieces


def whole(rows: list[list[object]]) -> str:
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerows(rows)
    return stream.getvalue()


@pytest.mark.parametrize("count", [0, 1, 3, 4, 5, 8, 9])
def test_pieces_join_to_the_whole_text_with_at_most_the_rows_of_a_piece(count: int) -> None:
    rows: list[list[object]] = [[f"s{i}", "a,b", 'say "hi"', "", 1.5, None] for i in range(count)]
    rows[1:2] = [[]] if count > 1 else rows[1:2]  # an empty row still writes its line end
    pieces = list(csv_pieces(rows, rows_per_piece=4))
    assert "".join(pieces) == whole(rows)
    assert all(piece.count("\n") <= 4 for piece in pieces)
    assert len([piece for piece in pieces if piece]) == -(-count // 4)
