"""The tokens reader gives the tree :func:`grader.model.expr.parse` gives for the joined tokens, or gives up.

The reference is Python's own parser through ``parse`` (never the reader): a table of shapes where Python's grammar
is easy to get wrong, and a property over random token sequences and over students' texts."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.base.errors import ExpressionError
from grader.grade.infix import read_tokens
from grader.grade.notation import ReadError, _written
from grader.model.expr import MAX_DEPTH, parse


def _parsed(tokens: list[str]) -> str:
    """What parse makes of the joined tokens: the tree's repr, or the error's message."""
    try:
        return repr(parse("".join(tokens)))
    except ExpressionError as error:
        return f"error: {error}"


SHAPES = [  # (text, tokens) that the reader reads as parse does
    "-p**2", "2**-p**2", "p--v", "+p", "-+-p", "p**v**2", "p/v/2", "p-v-2", "p*-v", "(p+v)*(p-v)/2",
    "sqrt(p)**2", "hypot(p,-v)", "Max(p,v)*2", "1e-3*p", "2.*p", ".5*p", "1.50*v", "100000000000000000000*p",
    "1E+2*v", "atan2(p,v)", "p**64", "p**-64", "p**-65.0", "pi*p", "((((p))))", "-(p)**2", "2*" * 10 + "p",
]

GIVEN_UP = [  # shapes left to parse (which reads them, or says what is wrong)
    "p**65", "p**65.5", "0123*p", "00*p", "1e999*p", "p**", "p*", "*p", "(p", "p)", "Max(p)", "Max(p,v,)",
    "sqrt(p,v)", "foo(p)", "None*p", "p*lambda", "(p,v)", "p//v", "p%v", "", "p<v", "٣*p", "３*p",
    "+".join(["p"] * (MAX_DEPTH + 2)), "(" * 60 + "p" + ")" * 60,
]


def _tokens(text: str) -> list[str]:
    import re

    return re.findall(r"\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|[A-Za-z_]\w*|\*\*|//|<=|[-+*/%(),<]", text)


@pytest.mark.parametrize("text", SHAPES)
def test_a_common_shape_is_read_as_parse_reads_it(text: str) -> None:
    tokens = _tokens(text)
    assert "".join(tokens) == text
    tree = read_tokens(tokens)
    assert tree is not None
    assert repr(tree) == _parsed(tokens)


@pytest.mark.parametrize("text", GIVEN_UP)
def test_an_unusual_or_wrong_shape_is_left_to_parse(text: str) -> None:
    tokens = _tokens(text)
    assert read_tokens(tokens) is None


def test_a_flat_sum_at_the_depth_limit_is_read() -> None:
    tokens = _tokens("+".join(["p"] * (MAX_DEPTH + 1)))
    assert repr(read_tokens(tokens)) == _parsed(tokens)


TOKENS = st.lists(st.sampled_from(["p", "v", "pi", "2", "0.5", "1e-3", "10", "3.", "+", "-", "*", "/", "**", "(",
                                   ")", ",", "sqrt", "Max", "hypot", "exp", "in", "0", "07"]), max_size=25)


@settings(max_examples=1000, deadline=None)
@given(TOKENS)
def test_random_tokens_are_read_as_parse_reads_them_or_left_to_it(tokens: list[str]) -> None:
    tree = read_tokens(tokens)
    if tree is not None:
        assert repr(tree) == _parsed(tokens)


TEXTS = st.text(alphabet="pve2 .01()+-*/^,×·sqrtMaxhyotxpin", max_size=40)


@settings(max_examples=1500, deadline=None)
@given(TEXTS, st.sampled_from([("p", "v"), ("p", "v", "e"), ("in", "p")]))
def test_a_students_text_is_read_as_parse_reads_it_or_left_to_it(text: str, symbols: tuple[str, ...]) -> None:
    try:
        tokens = _written(text, symbols)
    except ReadError:
        return
    tree = read_tokens(tokens)
    if tree is not None:
        assert repr(tree) == _parsed(tokens)
