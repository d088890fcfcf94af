"""Worked solutions read as a textbook writes them: the seed templates' steps against forms written by
hand from the textbook's conventions, and the rewriting never changes a value."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from grader.assign.variants import ProblemVariant
from grader.bank.template import Template
from grader.model.expr import Node, Num, Op, Sym, parse, to_text
from grader.model.kernel import evaluate
from grader.render.preview import example_printed
from grader.render.readable import Names, readable
from grader.render.typst_math import math
from grader.render.worked import WorkedStep, worked

# Each step as the key prints it (Typst math): the relation's equation where it is not already the
# solved form, then "unknown = solved form". Written by hand: numbers first, then masses, g, lengths,
# velocities, functions, sums, and (1 + e)-like sums last; one root of a product; the sign in front;
# 1/2 m v^2; no fraction inside a denominator.
GOLDEN: dict[str, list[tuple[str | None, str]]] = {
    "drop-rebound": [
        (None, 'v_"impact" = sqrt(2 g h_"drop")'),
        (None, 'T = 1/2 m v_"impact"^2'),
        ('-v\' = sqrt(2 g h_"rebound")', 'v\' = -sqrt(2 g h_"rebound")'),
        ('e = -v\'/v_"impact"', 'e = sqrt(h_"rebound"/h_"drop")'),  # Problem 3/251: e = √(h′/h)
        # energy with 1/2 m v^2 (Sample Problems 3/28-3/30): T, T' from the velocity after, then T - T'
        (None, "T' = 1/2 m v'^2"),
        (None, 'E_"lost" = T - T\''),
        (None, 'f_"loss" = E_"lost"/T'),
    ],
    "pile-driver": [
        (None, 'v_"ram" = sqrt(2 g h_"drop")'),
        (None, 'T = 1/2 m_"ram" v_"ram"^2'),
        ('-v\'_"ram" = sqrt(2 g h_"rebound")', 'v\'_"ram" = -sqrt(2 g h_"rebound")'),
        # Sample Problem 3/28 (a): conservation of momentum gives the pile's velocity; the impulse asked is the
        # pile's change of momentum
        ('m_"ram" v_"ram" = m_"ram" v\'_"ram" + m_"pile" v_"pile"',
         'v_"pile" = (m_"ram" (v_"ram" - v\'_"ram"))/m_"pile"'),
        (None, 'J = m_"pile" v_"pile"'),
        (None, 'e = (v_"pile" - v\'_"ram")/v_"ram"'),
        (None, 'T\' = 1/2 m_"ram" v\'_"ram"^2 + 1/2 m_"pile" v_"pile"^2'),
        (None, 'E_"lost" = T - T\''),
        (None, 'f_"loss" = E_"lost"/T'),
    ],
    "ball-plate": [
        (None, "v_t = v cos(theta)"),
        (None, "v_n = v sin(theta)"),
        ("e = -v'_n/v_n", "v'_n = -e v_n"),  # the textbook's (1): e applied to the normal components
        (None, "v'_t = v_t"),
        (None, 'v_"out" = sqrt(v\'_n^2 + v\'_t^2)'),
        ('tan(theta_"out") = -v\'_n/v\'_t', 'theta_"out" = tan^(-1)(-v\'_n/v\'_t)'),
    ],
    "car-collision": [
        # Problem 3/255: momentum (a) and restitution (b), solved together, in terms of p and v
        ("m v = m v'_A + p m v'_B", ''),
        ("e = (v'_B - v'_A)/v", ''),
        (None, "v'_A = (v (1 - p e))/(1 + p)"),
        (None, "v'_B = (v (1 + e))/(1 + p)"),
        (None, "v'_A/v = (0.6333 v)/v"),
        (None, "v'_B/v = (0.7333 v)/v"),
    ],
    "oblique-spheres": [
        (None, "v_(1, n) = v_1 cos(theta)"),
        (None, "v_(1, t) = v_1 sin(theta)"),
        # Sample Problem 3/30: (a) momentum along n, (b) restitution, then their simultaneous solution
        ("m_1 v_(1, n) = m_1 v'_(1, n) + m_2 v'_(2, n)", ''),
        ("e = (v'_(2, n) - v'_(1, n))/v_(1, n)", ''),
        (None, "v'_(1, n) = (v_(1, n) (m_1 - e m_2))/(m_1 + m_2)"),
        (None, "v'_(2, n) = (m_1 v_(1, n) (1 + e))/(m_1 + m_2)"),
        (None, "v'_(1, t) = v_(1, t)"),
        (None, "v'_(2, t) = 0"),
        (None, "T = 1/2 m_1 v_1^2"),
        # each speed after squared as its components squared and added: v'^2 = v'_n^2 + v'_t^2 (v'_(2, t) is 0)
        (None, "T' = 1/2 m_2 v'_(2, n)^2 + 1/2 m_1 (v'_(1, n)^2 + v'_(1, t)^2)"),
        (None, 'E_"lost" = T - T\''),
        (None, 'f_"loss" = E_"lost"/T'),
        (None, 'v_(1, "out") = sqrt(v\'_(1, n)^2 + v\'_(1, t)^2)'),
        ('tan(theta_(1, "out")) = v\'_(1, n)/v\'_(1, t)', 'theta_(1, "out") = tan^(-1)(v\'_(1, n)/v\'_(1, t))'),
        (None, 'v_(2, "out") = abs(v\'_(2, n))'),
    ],
}

# Problem bank II (issue 14), written by hand the same way. A speed before a perfectly plastic impact comes
# from conservation of momentum with the common speed after (m_b v = (m_b + m_blk) V), not from the
# impulse; a root of a quotient is one root, in front of the fraction of the rest: sqrt(2 h0/g) (1 + e)/(1 - e).
GOLDEN_BANK_II: dict[str, list[tuple[str | None, str]]] = {
    "successive-bounces": [
        (None, "h_n = e^(2 n) h_0"),
        (None, "D = (h_0 (1 + e^2))/(1 - e^2)"),
        (None, 't_"rest" = sqrt((2 h_0)/g) (1 + e)/(1 - e)'),
    ],
    "ballistic-pendulum": [
        (None, 'V = sqrt(2 g L (1 - cos(theta_"max")))'),
        ('m_b v_"bullet" = (m_b + m_"blk") V', 'v_"bullet" = ((m_b + m_"blk") V)/m_b'),
        (None, 'T = 1/2 m_b v_"bullet"^2'),
        (None, 'T\' = 1/2 (m_b + m_"blk") V^2'),  # a plastic impact: the two move on together
        (None, 'E_"lost" = T - T\''),
        (None, 'f_"loss" = E_"lost"/T'),
    ],
    "skid": [
        (None, "v_c = sqrt(2 mu_k g d)"),
        ("m_A v_A = (m_A + m_B) v_c", "v_A = ((m_A + m_B) v_c)/m_A"),
        (None, "T = 1/2 m_A v_A^2"),
        (None, "T' = 1/2 (m_A + m_B) v_c^2"),
        (None, 'E_"lost" = T - T\''),
        (None, 'f_"loss" = E_"lost"/T'),
    ],
    "wall-throw": [
        (None, "v_x = v_0 cos(alpha)"),
        (None, "v_y = v_0 sin(alpha)"),
        ("D = v_x t_1", "t_1 = D/v_x"),
        (None, 'y_"hit" = h_0 + v_y t_1 - 1/2 g t_1^2'),
        (None, 'v_(y, "hit") = v_y - g t_1'),
        (None, 'v_"hit" = sqrt(v_x^2 + v_(y, "hit")^2)'),
        ("e = -v'_x/v_x", "v'_x = -e v_x"),
        (None, 'v\'_y = v_(y, "hit")'),
        (None, 'v_"out" = sqrt(v\'_x^2 + v\'_y^2)'),
        ('0 = y_"hit" + v\'_y t_2 - 1/2 g t_2^2', 't_2 = (v\'_y + sqrt(v\'_y^2 + 2 g y_"hit"))/g'),
        (None, 'x_"land" = -v\'_x t_2'),
    ],
}


def example_variant(template: Template) -> ProblemVariant:
    printed = example_printed(template)
    return ProblemVariant("1", template.id, "golden", {n: float(v) for n, v in printed.items()}, printed, ())


@pytest.mark.parametrize("template_id", GOLDEN)
def test_the_seed_templates_steps_read_as_the_textbook_writes_them(template_id: str,
                                                                   bank: dict[str, Template]) -> None:
    steps = worked(bank[template_id], example_variant(bank[template_id])).steps
    assert [(step.equation, _chain(step)) for step in steps] == GOLDEN[template_id]


@pytest.mark.parametrize("template_id", GOLDEN_BANK_II)
def test_bank_ii_steps_read_as_the_textbook_writes_them(template_id: str, bank: dict[str, Template]) -> None:
    steps = worked(bank[template_id], example_variant(bank[template_id])).steps
    assert [(step.equation, _chain(step)) for step in steps] == GOLDEN_BANK_II[template_id]


def _chain(step: WorkedStep) -> str:
    """A step's quantity and form; a block's labelled equation has none (its values come with the solution)."""
    return f"{step.chain[0]} = {step.chain[1]}" if step.chain else ""


@pytest.mark.parametrize(("template_id", "unknown", "relation", "substituted"), [
    ("ballistic-pendulum", 'v_"bullet"', "conservation of momentum", "((0.01200 + 4.00) dot 1.376)/0.01200"),
    ("skid", "v_A", "conservation of momentum", "((1500 + 1200) dot 10.00)/1500"),
    ("successive-bounces", 't_"rest"', "total time", "sqrt((2 dot 1.80)/9.81) (1 + 0.75)/(1 - 0.75)"),
    ("wall-throw", "t_2", "the landing is the root with +, since the root with − is not positive",
     "(2.010 + sqrt(2.010^2 + 2 dot 9.81 dot 3.342))/9.81"),
])
def test_bank_ii_steps_say_their_route_and_take_the_numbers(template_id: str, unknown: str, relation: str,
                                                            substituted: str, bank: dict[str, Template]) -> None:
    """The momentum step names its law, the landing time says which root and why, and the numbers
    go into the readable form in its order."""
    steps = {step.chain[0]: step for step in worked(bank[template_id], example_variant(bank[template_id])).steps}
    assert relation in str(steps[unknown].relation)
    assert steps[unknown].chain[2] == substituted


def test_numbers_are_put_in_the_same_order(bank: dict[str, Template]) -> None:
    """The substituted line follows the readable form: the pile driver's rebound and energies."""
    solution = worked(bank["pile-driver"], example_variant(bank["pile-driver"]))
    steps = {step.chain[0]: step.chain for step in solution.steps}
    assert steps['v\'_"ram"'][2] == "-sqrt(2 dot 9.81 dot 0.10)"
    assert steps["T'"][2] == "1/2 dot 800 (-1.401)^2 + 1/2 dot 2400 dot 2.555^2"
    assert steps['E_"lost"'][2] == "15700 - 8618"
    assert steps["T"][2] == "1/2 dot 800 dot 6.264^2"


NAMES = Names({"m": (0, 1, 0, 0), "M": (0, 1, 0, 0), "g": (1, 0, -2, 0), "h": (1, 0, 0, 0), "v": (1, 0, -1, 0),
               "u": (1, 0, -1, 0), "e": (0, 0, 0, 0), "J": (1, 1, -1, 0), "theta": (0, 0, 0, 1)},
              ["m", "M", "h", "u", "v", "e"])


@pytest.mark.parametrize(("source", "expected"), [
    ("-sqrt(2)*sqrt(h)*sqrt(g)", "-sqrt(2*g*h)"),  # one root, the sign in front
    ("sqrt(h)/sqrt(g)", "sqrt(h/g)"),  # one root of a quotient
    ("sqrt(2)*sqrt(h)*(e + 1)/(sqrt(g)*(1 - e))", "sqrt(2*h/g)*((1 + e)/(1 - e))"),  # in front of the fraction
    ("v/sqrt(g)", "v/sqrt(g)"),
    ("v*(m + M)/m", "(m + M)*v/m"),  # a sum of masses stands with the masses
    ("M*(m + M)", "M*(m + M)"),  # after the masses alone
    ("v*m*(e + 1)", "m*v*(1 + e)"),  # masses, velocities, then (1 + e)
    ("(e + 1)*(u + v)*m", "m*(u + v)*(1 + e)"),  # a sum with a dimension before a pure one
    ("cos(theta)*v", "v*cos(theta)"),
    ("M*m", "m*M"),  # the order the problem introduces them in
    ("-J/m + v", "v - J/m"),  # positive terms first
    ("J/M + u", "u + J/M"),  # simple terms first
    ("-(e - 1)*(e + 1)*m*v**2/2", "1/2*m*v**2*(1 - e**2)"),
    ("v*v/(2*g)", "v**2/(2*g)"),
    ("(1 - e)*v/(2/m + 2/M)", "v*(1 - e)/(2*(1/m + 1/M))"),  # a common whole number taken out
    ("-2*u - 4*v", "-2*(u + 2*v)"),
    ("m*hypot(u, v)*hypot(u, v)/2", "1/2*m*(u**2 + v**2)"),
    ("v*(1 - 0.1*p)/(p + 1)", "v*(1 - 0.1*p)/(1 + p)"),  # the data's decimals stay decimals
    ("0.3*m*v", "0.3*m*v"),
    ("h", "h"),
    # Issue 32: the key printed "1/4 p" and left a mass above and below uncancelled
    ("p/4", "p/4"),
    ("v*(1 - p/4)/(p + 1)", "v*(1 - p/4)/(1 + p)"),
    ("3*e*v/4", "3*e*v/4"),
    ("m*v/2", "m*v/2"),  # a half that is not an energy's
    ("m*M/(m*(m + M))", "M/(m + M)"),
    ("m**2*v/(m*M)", "m*v/M"),
    ("m*v*(1 + e)/(m*(m + M))", "v*(1 + e)/(m + M)"),
])
def test_readable_rewrites(source: str, expected: str) -> None:
    assert to_text(readable(parse(source), NAMES)) == expected


def test_a_leading_half_is_printed_before_the_factors() -> None:
    assert math(readable(parse("m*v*v/2"), NAMES)) == "1/2 m v^2"
    assert math(readable(parse("m*v*v/2"), NAMES), {"m": "2.0", "v": "3.1"}) == "1/2 dot 2.0 dot 3.1^2"


LEAVES = st.sampled_from([Sym("m"), Sym("M"), Sym("h"), Sym("v"), Sym("u"), Sym("e"), Sym("g"),
                          Num(Fraction(1)), Num(Fraction(2)), Num(Fraction(1, 2)), Num(Fraction(-3))])


def _trees(children: st.SearchStrategy[Node]) -> st.SearchStrategy[Node]:
    binary = st.tuples(st.sampled_from(["add", "sub", "mul", "div"]), children, children).map(
        lambda t: Op(t[0], (t[1], t[2])))
    unary = st.tuples(st.sampled_from(["neg", "sqrt", "cos"]), children).map(lambda t: Op(t[0], (t[1],)))
    square = children.map(lambda c: Op("pow", (c, Num(Fraction(2)))))
    return st.one_of(binary, unary, square, st.tuples(children, children).map(lambda t: Op("hypot", t)))


@settings(max_examples=400, deadline=None)
@given(tree=st.recursive(LEAVES, _trees, max_leaves=10),
       values=st.lists(st.floats(0.3, 3.0), min_size=7, max_size=7))
def test_readable_never_changes_a_value(tree: Node, values: list[float]) -> None:
    """Wherever the expression has a value, the rewritten one has the same (radicands positive: the
    roots merge as they do for the quantities of a scene, which are positive where they are rooted)."""
    env = {name: np.float64(value) for name, value in zip("mMhvueg", values, strict=True)}
    with np.errstate(all="ignore"):
        before = float(evaluate(tree, env))
        if not np.isfinite(before) or _roots_of_negatives(tree, env):
            return
        after = float(evaluate(readable(tree, NAMES), env))
    assert after == pytest.approx(before, rel=1e-9, abs=1e-9 * max(1.0, abs(before))), to_text(readable(tree, NAMES))


def _roots_of_negatives(node: Node, env: dict[str, np.float64]) -> bool:
    """Whether a root's factors are not all positive (sqrt(a) sqrt(b) = sqrt(a b) needs a, b >= 0)."""
    if not isinstance(node, Op):
        return False
    if node.op == "sqrt" and _has_negative_factor(node.args[0], env):
        return True
    return any(_roots_of_negatives(arg, env) for arg in node.args)


def _has_negative_factor(node: Node, env: dict[str, np.float64]) -> bool:
    if isinstance(node, Op) and node.op in ("mul", "div"):
        return any(_has_negative_factor(arg, env) for arg in node.args)
    with np.errstate(all="ignore"):
        return not float(evaluate(node, env)) >= 0
