"""Symbolic answers cannot be gamed (issue 22, item 3): wrong answers crafted to agree with the key at a few
sampled points are ``incorrect``, or ``invalid`` for a function a physical answer never needs; honest
rewritings of the key stay ``correct``. The keys are car-collision's (``problem_bank/car-collision.yaml``)."""

from __future__ import annotations

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from grader.grade.check import check, expectation

VA = "v*(1 - 0.1*p)/(p + 1)"  # e = 0.1
VB = "1.1*v/(p + 1)"
DOMAINS = {"p": (0.3, 3.0), "v": (1.0, 10.0)}

ADVERSARIAL = [
    # The three.
    (VA, "v(1-0.07p)/(p+1) + 100*Max(0, p-2.99)", "invalid"),
    (VA, "v(1-0.1p)/(p+1) + 50*exp(-1000000*(p-1.7)^2)", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 5*(1+sign(p-2.95))", "invalid"),
    # Refused functions, whatever they would have done.
    (VA, "v(1-0.1p)/(p+1) + Min(0, p-0.31)", "invalid"),
    (VA, "v(1-0.1p)/(p+1) + 5*abs(p-2.95) - 5*(p-2.95)", "invalid"),
    (VA, "v(1-0.1p)/(p+1) + 5*atan2(p-2.95, -1)", "invalid"),
    (VB, "1.1v/(p+1) + sqrt(p-2.95+abs(p-2.95))", "invalid"),
    # Narrow bumps, in one name and in two.
    (VA, "v(1-0.1p)/(p+1) + 50*exp(-10^12*(p-1.7)^2)", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 50*exp(-10^12*((p-1.7)^2 + (v-3.3)^2))", "incorrect"),
    (VB, "1.1v/(p+1) + 1000*v*exp(-1e8*(p-1.7)^2)", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 10*exp(-1/(p-2.99)^2)", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 0.5*(1+cos(pi*(p-1.7)*10^6))*exp(-10^6*(p-1.7)^2)", "incorrect"),
    (VB, "1.1v/(p+1) + 1e-15/((p-1.7)^2 + 1e-30)", "incorrect"),  # a rational bump: no function at all
    (VB, "1.1v/(p+1) + 1e-40/((p-1.7)^2 + 1e-80)", "incorrect"),
    (VB, "1.1v/(p+1) + 1/(1e-9 + 1e9*(p-1.7)^2)", "incorrect"),
    # Steps and ramps built from allowed functions.
    (VA, "v(1-0.1p)/(p+1) + 5*(1 + (p-2.95)/sqrt((p-2.95)^2))", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 50*(p-2.99 + hypot(p-2.99, 0))", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 5/(1 + exp(-10^9*(p-2.95)))", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 10*log(1 + exp(10^6*(p-2.99)))/10^6", "incorrect"),
    (VB, "1.1v/(p+1) + sqrt((p-2.95)^2) - (p-2.95)", "incorrect"),
    (VB, "1.1v/(p+1) + ((p-2.95)^2)^0.5 - (p-2.95)", "incorrect"),
    (VB, "1.1v/(p+1) + 1e6*(sqrt((p-2.99)^2) + (p-2.99))", "incorrect"),
    (VB, "1.1v/(p+1)*(1 + (v-9.99+sqrt((v-9.99)^2)))", "incorrect"),
    # Terms that are small at most points and large somewhere, or oscillate fast.
    (VA, "v(1-0.1p)/(p+1) + 1e-9*p^50", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 1e-30*p^64", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + sin(1000*pi*p)", "incorrect"),
    (VA, "v(1-0.1p)/(p+1) + 0.001*sin(1000000*pi*p)", "incorrect"),
    (VB, "1.1v/(p+1) + 1/tan(pi*(p-1.7)*1e7)^-1", "incorrect"),
    (VB, "1.1v/(p+1) + sin(pi*v)^2*1e-3", "incorrect"),
    (VB, "1.1v/(p+1) + (p-0.3)*(p-3)*(v-1)*(v-10)*1e-3", "incorrect"),  # zero on the domain's edges
    # Small slips an eye would miss.
    (VA, "v*(1-0.1001p)/(p+1)", "incorrect"),
    (VA, "v*(1-0.1p)/(p+1.001)", "incorrect"),
    (VB, "1.1v/(p+1) + 1e-3", "incorrect"),
    (VB, "1.1v/(p-1)", "incorrect"),
    (VB, "1.1v/(p+1)^1.0001", "incorrect"),
]

HONEST = [
    (VA, "v*(1 - 0.1*p)/(p + 1)"), (VA, "(v - 0.1*p*v)/(1 + p)"), (VA, "v/(p+1)*(1-0.1p)"),
    (VA, "v(1-p/10)/(1+p)"), (VA, "v*(10-p)/(10*(p+1))"), (VA, "(v-0.1pv)/(p+1)"), (VA, "v(1-0.1p)(p+1)^-1"),
    (VA, "v/(p+1) - 0.1 p v/(p+1)"), (VA, "(1-0.1*p)*v/(1+p)"), (VA, "v*(1 - 11/10 * p/(p+1))"),
    (VB, "1.1*v/(p + 1)"), (VB, "11/10*v/(1+p)"), (VB, "11v/(10p+10)"), (VB, "1.1 v (p+1)^-1"),
    (VB, "v*exp(log(1.1))/(p+1)"), (VB, "1.1*v*sqrt(1/(p+1)^2)"),
    (VA, "sqrt(v^2*(1-0.1p)^2/(p+1)^2)"),  # 1 - 0.1p > 0 on the domain: the exact check knows where p lies
]


def _verdict(key: str, answer: str) -> dict[str, object]:
    return check(answer, expectation(key, symbols=["p", "v"], domains=DOMAINS))


@pytest.mark.parametrize(("key", "answer", "verdict"), ADVERSARIAL)
def test_a_crafted_wrong_answer_does_not_pass(key: str, answer: str, verdict: str) -> None:
    result = _verdict(key, answer)
    assert result["verdict"] == verdict, result["feedback"]
    if verdict == "invalid":
        assert "is not accepted in this answer" in str(result["feedback"])


@pytest.mark.parametrize(("key", "answer"), HONEST)
def test_an_honest_form_stays_correct(key: str, answer: str) -> None:
    result = _verdict(key, answer)
    assert result["verdict"] == "correct", result["feedback"]


def test_the_list_is_long_enough() -> None:
    assert len(ADVERSARIAL) >= 30


def test_a_refused_function_is_accepted_when_the_key_uses_it() -> None:
    result = check("Max(p, v)", expectation("Max(v, p)", symbols=["p", "v"], domains=DOMAINS))
    assert result["verdict"] == "correct"



_TERMS = st.sampled_from(["v", "p", "p*v", "v/(p + 1)", "v^2/(2*p + 3)", "sqrt(p*v)", "exp(-p/4)*v", "sin(p)*v",
                          "(1 - 0.1*p)*v/(p + 1)", "v*p^3", "1/(v + 0.5)"])


@settings(max_examples=60, deadline=None)
@given(terms=st.lists(_TERMS, min_size=1, max_size=3), scale=st.integers(2, 999),
       rewrite=st.sampled_from(["({key})*{c}/{c}", "{c}*({key})/{c}", "({key}) + p - p", "1/(1/({key}))",
                                "({key})*(p + {c})/(p + {c})"]))
def test_an_honest_rewriting_of_any_key_is_correct(terms: list[str], scale: int, rewrite: str) -> None:
    """What refuses the crafted answers never refuses an honest one: a key made of a few terms (rational,
    roots, exponentials, sines), rewritten without changing its value, stays correct."""
    key = " + ".join(terms)
    answer = rewrite.format(key=key, c=scale)
    assume("1/(1/" not in answer or "sin" not in key)  # a sine's zeros make 1/(1/x) undefined there, as it is
    result = _verdict(key, answer)
    assert result["verdict"] == "correct", (answer, result["feedback"])


@settings(max_examples=60, deadline=None)
@given(centre=st.floats(0.31, 2.99), width=st.integers(3, 12), height=st.sampled_from([0.01, 1.0, 100.0]),
       shape=st.sampled_from(["{h}*exp(-((p - {c})*10^{w})^2)", "{h}/(1 + ((p - {c})*10^{w})^2)",
                              "{h}*(1 + (p - {c})/sqrt((p - {c})^2))", "{h}/(1 + exp(-(p - {c})*10^{w}))",
                              "{h}*exp(-((p - {c})^2 + (v - 5.5)^2)*10^{w})", "{h}*v/(1 + ((v - 1 - 3*{c})*10^{w})^2)",
                              "{h}*exp(-((p*v - 3*{c})*10^{w})^2)"]))
def test_a_bump_or_a_step_anywhere_in_the_domain_is_found(centre: float, width: int, height: float,
                                                            shape: str) -> None:
    """A narrow bump or a step hidden between the sampled points, wherever it is, however narrow."""
    answer = f"{VA} + " + shape.format(h=height, c=round(centre, 4), w=width)
    assert _verdict(VA, answer)["verdict"] == "incorrect", answer
