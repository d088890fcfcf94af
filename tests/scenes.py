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

TWO_BOUNCES = """
id: two-bounces
title: A ball bounces twice
version: 1
gravity: 9.81 m/s^2
bodies: {ball: {mass: m}, floor: {fixed: true}}
symbols: {m: {unit: kg}}
parameters:
  h_drop: {unit: m, domain: "(0, inf)", sample: {uniform: [1, 2]}, decimals: 2}
  e: {unit: "", domain: "[0, 1]", sample: {uniform: [0.5, 0.9]}, decimals: 2}
  J: {unit: m, domain: "[0, 1]", sample: {uniform: [0, 1]}, decimals: 2, description: "named like an impulse"}
stages:
  - {effect: free_fall, body: ball, height: h_drop, speed: v1}
  - {effect: impact, bodies: [ball, floor], restitution: e, before: {ball: v1}, after: {ball: w1}}
  - {effect: rise, body: ball, speed: -w1, height: h1}
  - {effect: free_fall, body: ball, height: h1, speed: v2}
  - {effect: impact, bodies: [ball, floor], restitution: e, before: {ball: v2}, after: {ball: w2}, loss_fraction: f2}
  - {effect: rise, body: ball, speed: -w2, height: h2}
answers:
  h2: {value: h2, unit: m}
  f2: {value: f2, unit: ""}
  J_plus_h2: {value: J + h2, unit: m}
statement: Dropped from {{ h_drop }} m with e = {{ e }}.
"""

RAM_AND_PILE = """
id: ram-and-pile
title: A ram dropped onto a pile, heights in HEIGHT
version: 1
gravity: GRAVITY
bodies: {ram: {mass: m_ram}, pile: {mass: m_pile}}
parameters:
  m_ram: {unit: kg, domain: "(0, inf)", sample: {uniform: [600, 1000]}, sig_figs: 3}
  m_pile: {unit: kg, domain: "(0, inf)", sample: {uniform: [2400, 3000]}, sig_figs: 3}
  h_drop: {unit: HEIGHT, domain: "(0, inf)", sample: {uniform: [1.5, 3]}, sig_figs: 3}
  h_rebound: {unit: HEIGHT, domain: "[0, inf)", sample: {uniform: [0.05, 0.2]}, sig_figs: 3}
stages:
  - {effect: free_fall, body: ram, height: h_drop, speed: v_ram}
  - {effect: impact, bodies: [ram, pile], restitution: e, before: {ram: v_ram}, after: {ram: v_back, pile: v_pile}}
  - {effect: rise, body: ram, speed: -v_back, height: h_rebound}
answers:
  v_pile: {value: v_pile, unit: SPEED}
  e: {value: e, unit: ""}
statement: The ram falls {{ h_drop }} HEIGHT and rebounds {{ h_rebound }} HEIGHT.
"""
"""Sample Problem 3/28's pile driver with other units: replace HEIGHT, GRAVITY and SPEED (``mm``,
``9.81 m/s^2``, ``m/s``; or ``ft``, ``32.2 ft/s^2``, ``ft/s``)."""
