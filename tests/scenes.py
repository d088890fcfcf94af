"""Small scenes that tests share (YAML text; parse with grader.bank.template.parse_template)."""

TWO_BODIES = """
id: two-bodies
title: Two bodies on a line
version: 1
bodies: {a: {mass: m1}, b: {mass: m2}}
parameters:
  m1: {unit: kg, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 1}
  m2: {unit: kg, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 1}
  u1: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [1, 2]}, decimals: 1}
  u2: {unit: m/s, domain: "(-inf, inf)", sample: {uniform: [-2, -1]}, decimals: 1}
  e: {unit: "", domain: "[0, 1]", sample: {uniform: [0.2, 0.8]}, decimals: 2}
stages:
  - {effect: impact, bodies: [a, b], restitution: e, before: {a: u1, b: u2}, after: {a: a1, b: a2}}
answers:
  a1: {value: a1, unit: m/s}
  a2: {value: a2, unit: m/s}
statement: Two bodies collide.
"""
