"""The compiled kernels: the same numbers as evaluating each tree, with less work.

A :class:`Kernel` shares common subtrees, folds constants and writes into arrays nothing reads
any more; none of that may change a bit of any result, on ordinary or extreme inputs.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pytest

from grader.bank.template import Template
from grader.model import kernel as kernel_module
from grader.model.expr import Node, parse
from grader.model.kernel import Kernel, cosd, evaluate, sind
from grader.solve.compiled import Compiled

EXTREMES = [0.0, -0.0, 1e-300, 5e-324, 1e-150, 1e170, 1e300, -1e170, 1.0, 1 - 1e-12, 90.0, 180.0, 270.0, -90.0,
            360.0, 720.0, 45.0, 1e16, np.inf, -np.inf, np.nan]


def reference_sind(degrees: Any) -> Any:
    """sind as it was first written (numpy.choose over quadrants from numpy.mod): the definition."""
    quarter, sine, cosine = _reference_quadrant(degrees)
    return np.choose(quarter, [sine, cosine, -sine, -cosine]) + 0.0


def reference_cosd(degrees: Any) -> Any:
    """cosd as it was first written."""
    quarter, sine, cosine = _reference_quadrant(degrees)
    return np.choose(quarter, [cosine, -sine, -cosine, sine]) + 0.0


def _reference_quadrant(degrees: Any) -> tuple[Any, Any, Any]:
    x = np.asarray(degrees, dtype=float)
    finite = np.isfinite(x)
    reduced = np.fmod(np.where(finite, x, 0.0), 360.0)
    quarter = np.round(reduced / 90.0)
    radians = (reduced - 90.0 * quarter) * (np.pi / 180.0)
    return (np.mod(quarter, 4).astype(int), np.where(finite, np.sin(radians), np.nan),
            np.where(finite, np.cos(radians), np.nan))


def same_bits(ours: Any, reference: Any) -> bool:
    """Equal values, NaN where NaN, and the same sign of zero."""
    ours, reference = np.asarray(ours), np.asarray(reference)
    return bool(ours.shape == reference.shape and np.array_equal(ours, reference, equal_nan=True)
                and np.array_equal(np.signbit(ours), np.signbit(reference)))


def angles() -> np.ndarray:
    rng = np.random.default_rng(11)
    special = np.arange(-1080.0, 1081.0, 7.5)
    near = np.concatenate([np.nextafter(special, np.inf), np.nextafter(special, -np.inf)])
    return np.concatenate([rng.uniform(-1e5, 1e5, 5000), rng.uniform(-400, 400, 5000), rng.uniform(0, 90, 5000),
                           special, near, EXTREMES])


@pytest.mark.parametrize("ours, reference", [(sind, reference_sind), (cosd, reference_cosd)], ids=["sind", "cosd"])
def test_degree_trig_matches_its_first_definition_bit_for_bit(ours: Any, reference: Any) -> None:
    """The faster reduction (no fmod below 360 degrees, & 3 for mod 4) changes no bit, arrays or scalars."""
    with np.errstate(all="ignore"):
        assert same_bits(ours(angles()), reference(angles()))
        assert same_bits(ours(np.array([])), reference(np.array([])))
        for value in EXTREMES:
            assert type(ours(value)) is type(reference(value))
            assert same_bits(ours(value), reference(value)), value


def columns(template: Template, count: int, extreme: bool) -> dict[str, np.ndarray]:
    """Parameter columns: sampled, or drawn from extreme magnitudes (refused rows included)."""
    rng = np.random.default_rng(7)
    table = {}
    for name, parameter in template.parameters.items():
        low, high = min(parameter.sample.values), max(parameter.sample.values)
        column = rng.uniform(low, high, count)
        if extreme:
            column[: len(EXTREMES)] = EXTREMES
            rng.shuffle(column)
        table[name] = column
    return table


def trees_of(compiled: Compiled) -> dict[Any, Node]:
    """Every tree a compiled template evaluates, as the solver names them."""
    kernel = compiled.kernel
    found = {}
    for index, check in enumerate(compiled.checks):
        found["holds", index] = check.holds
        if check.subject is not None:
            found["subject", index] = check.subject
    for name, answer in compiled.answers.items():
        found.update({("undefined", name, i): rule.when for i, rule in enumerate(answer.undefined)})
        if answer.numeric is not None:
            found["answer", name] = answer.numeric
    assert set(found) == set(kernel.roots)
    return found


# Columns shorter than the kernel's threshold take the body that allocates every result; longer ones the
# body that writes into arrays nothing reads any more, and beyond one block that body runs a block at a
# time (the last one partial): each must give evaluate's numbers.
SIZES = [kernel_module._SHORT // 2, kernel_module._SHORT + 904, 2 * kernel_module._BLOCK + 904]
SIZE_IDS = ["short", "long (in place)", "blocks"]


@pytest.mark.parametrize("size", SIZES, ids=SIZE_IDS)
@pytest.mark.parametrize("extreme", [False, True], ids=["sampled", "extreme"])
def test_kernel_gives_evaluate_s_numbers_bit_for_bit_for_every_template(
        bank: dict[str, Template], compiled: dict[str, Compiled], extreme: bool, size: int) -> None:
    """Shared subtrees, folded constants and reused arrays change nothing, NaN and -0 included. (A template
    solved numerically is checked here at the short size; in place and beyond one block in the slow run, where
    the reference ``evaluate`` of its root scans takes 5 to 40 s.)"""
    _same_as_evaluate(bank, compiled, extreme, size, numeric=size == SIZES[0])


@pytest.mark.slow
@pytest.mark.parametrize("size", SIZES[1:], ids=SIZE_IDS[1:])
@pytest.mark.parametrize("extreme", [False, True], ids=["sampled", "extreme"])
def test_kernel_gives_evaluate_s_numbers_in_place_and_beyond_one_block_for_templates_solved_numerically(
        bank: dict[str, Template], compiled: dict[str, Compiled], extreme: bool, size: int) -> None:
    numeric = {t for t in bank if any(step.numeric for step in compiled[t].steps)}
    assert numeric, "no template of the bank is solved numerically: this check checks nothing"
    _same_as_evaluate({t: bank[t] for t in numeric}, compiled, extreme, size, numeric=True)


def _same_as_evaluate(bank: dict[str, Template], compiled: dict[str, Compiled], extreme: bool, size: int,
                      numeric: bool) -> None:
    for template_id, template in bank.items():
        if not numeric and any(step.numeric for step in compiled[template_id].steps):
            continue
        table = columns(template, size, extreme)
        env = {**table, **compiled[template_id].constants}
        kernel = compiled[template_id].kernel
        with np.errstate(all="ignore"):
            results = kernel(table)
            for key, tree in trees_of(compiled[template_id]).items():
                assert same_bits(np.broadcast_to(results[key], (size,)),
                                 np.broadcast_to(evaluate(tree, env), (size,))), (template_id, key)
            scalars = {name: float(column[0]) for name, column in table.items()}  # not arrays: no out=
            one_row = kernel(scalars)
            for key, tree in trees_of(compiled[template_id]).items():
                reference = evaluate(tree, {**scalars, **compiled[template_id].constants})
                assert same_bits(one_row[key], reference), key
                assert type(one_row[key]) is type(reference), key  # numbers stay numbers (no 0-d arrays)


@pytest.mark.parametrize("size", SIZES, ids=SIZE_IDS)
@pytest.mark.parametrize("template_id", ["oblique-spheres", "drop-rebound", "offset-spheres"])
def test_kernel_never_writes_into_its_inputs_or_earlier_results(compiled: dict[str, Compiled], template_id: str,
                                                                size: int) -> None:
    """Arrays are reused within one call only, never the caller's columns, a constant or a returned result."""
    kernel = compiled[template_id].kernel
    rng = np.random.default_rng(3)
    table = {name: rng.uniform(1, 80, size) for name in kernel.inputs}
    before = {name: column.copy() for name, column in table.items()}
    with np.errstate(all="ignore"):
        first = {key: np.array(value, copy=True) for key, value in kernel(table).items()}
        again = kernel(table)  # held, not copied: the next call's scratch arrays must not be these
        kernel({name: column * 2 for name, column in table.items()})
    assert all(np.array_equal(table[name], before[name]) for name in table)
    assert all(same_bits(again[key], first[key]) for key in first)


def test_kernel_called_from_threads_at_once_gives_each_call_its_own_numbers(compiled: dict[str, Compiled]) -> None:
    """Scratch arrays are kept between calls: two calls at once (numpy lets threads run in its loops)
    must each get their own, so each call's numbers are those it gives alone."""
    kernel = compiled["offset-spheres"].kernel
    rng = np.random.default_rng(5)
    tables = [{name: rng.uniform(1, 80, 3 * kernel_module._BLOCK) for name in kernel.inputs} for _ in range(4)]

    def call(table: dict[str, Any]) -> dict[Any, Any]:
        with np.errstate(all="ignore"):  # numpy's error state is the thread's own
            return kernel(table)

    alone = [call(table) for table in tables]
    with ThreadPoolExecutor(4) as pool:
        together = list(pool.map(call, tables * 5))
    for index, results in enumerate(together):
        assert all(same_bits(results[key], alone[index % 4][key]) for key in results), index


def test_constants_keep_their_values_and_results_that_need_no_input_are_numbers() -> None:
    """Constants reach numpy as read-only 0-d arrays (faster than Python floats on short columns): the
    numbers are those of Python floats, a second call sees the same constants, and a result that depends
    on no input is returned as the number it is."""
    kernel = Kernel({"a": parse("100*Max(0, x - y)/x"), "b": parse("2*g"), "c": parse("x/g + g")}, {"g": 9.81})
    for size in SIZES:
        x, y = np.linspace(-3.0, 7.0, size), np.linspace(7.0, -3.0, size)
        with np.errstate(all="ignore"):
            for _ in range(2):
                results = kernel({"x": x, "y": y})
                assert same_bits(results["a"], 100.0 * np.maximum(0.0, x - y) / x)
                assert same_bits(results["c"], x / 9.81 + 9.81)
    assert results["b"] == 2 * 9.81 and type(results["b"]) is type(evaluate(parse("2*g"), {"g": 9.81})) is np.float64
    assert results["c"] is not x
    one = kernel({"x": 2.0, "y": 1.0})
    assert one["a"] == 50.0 and type(one["a"]) is np.float64 and type(one["b"]) is np.float64


def test_common_subtrees_are_computed_once() -> None:
    """sqrt(h) used six times is one step; sind and cosd of one angle share one reduction."""
    tree = parse("(sqrt(h) + sqrt(r))/sqrt(h) + m*(sqrt(h) + sqrt(r))/M + 100*(sqrt(h) + sqrt(r))")
    assert len(Kernel({"a": tree})) == 9  # sqrt twice, then + / * / + * +: nothing twice
    assert len(Kernel({"a": parse("hypot(e*sind(t), cosd(t))"), "b": parse("atan2(e*sind(t), cosd(t))")})) == 6
    assert len(Kernel({"a": parse("sqrt(2)*sqrt(g)*x")}, {"g": 9.81})) == 1  # sqrt(2)*sqrt(g) folded


def test_constraint_with_three_conditions_checks_all_three() -> None:
    """Regression: numpy's logical_and took a third condition as its output array, so `a and b and c`
    ignored c (and wrote over it); conditions are now joined two at a time."""
    tree = parse("x > 0 and y > 0 and z > 0", allow_compare=True)
    env = {"x": np.array([1.0, 1.0]), "y": np.array([1.0, 1.0]), "z": np.array([-1.0, 1.0])}
    assert evaluate(tree, env).tolist() == [False, True]
    assert Kernel({"ok": tree})(env)["ok"].tolist() == [False, True]


@pytest.mark.parametrize("limit", [0.0, -0.0, 1.5, -np.inf, np.inf], ids=str)
def test_a_number_first_in_max_and_min_gives_numpy_s_result(limit: float) -> None:
    """The kernel's Max(0, x) takes another route than numpy.maximum(0.0, x); equal values, -0.0,
    NaN and infinities come out as numpy gives them."""
    special = np.array([-0.0, 0.0, 1.5, -1.5, np.nan, np.inf, -np.inf, 5e-324, -5e-324])
    for values in (special, np.tile(special, 200)):  # short arrays take numpy's own loop
        for name, function in (("Max", np.maximum), ("Min", np.minimum)):
            kernel = Kernel({"r": parse(f"{name}(c, x)")}, {"c": limit})
            with np.errstate(all="ignore"):
                assert same_bits(kernel({"x": values.copy()})["r"], function(limit, values)), name


@pytest.mark.parametrize("size", SIZES, ids=SIZE_IDS)
def test_every_kind_of_result_comes_back_whole_from_the_blocks(size: int) -> None:
    """A result that is an input, a number, a float written in place, the same tree under two names
    (written once, copied once) and a truth value (copied): each is the whole column, as evaluate gives it."""
    trees = {"input": parse("x"), "number": parse("2*g"), "float": parse("sqrt(x)*g"), "again": parse("sqrt(x)*g"),
             "truth": parse("x > 1", allow_compare=True), "angle": parse("cosd(x)")}
    kernel = Kernel(trees, {"g": 9.81})
    x = np.linspace(-400.0, 400.0, size)
    with np.errstate(all="ignore"):
        results = kernel({"x": x})
        for name, tree in trees.items():
            reference = evaluate(tree, {"x": x, "g": 9.81})
            assert same_bits(results[name], reference) and np.shape(results[name]) == np.shape(reference), name
    assert results["input"] is x


def test_angles_within_45_degrees_skip_the_reduction_with_the_same_bits() -> None:
    """sind and cosd of angles all within ±45° take a short path; one angle outside sends the same angles
    through the quadrant reduction, which must give every value to the bit (signed zeros included)."""
    inside = np.concatenate([np.random.default_rng(7).uniform(-45, 45, 5000),
                             [45.0, -45.0, 0.0, -0.0, 1e-300, -5e-324, 30.0, -15.0, np.nextafter(45.0, 0.0)]])
    with_outside = np.append(inside, 100.0)
    for function in (sind, cosd):
        short, reduced = function(inside), function(with_outside)[:-1]
        assert np.array_equal(short.view(np.int64), reduced.view(np.int64)), function.__name__
        assert all(np.float64(function(float(x))).view(np.int64) == r.view(np.int64)
                   for x, r in zip(inside[-9:], reduced[-9:], strict=True))
