"""The catalogue of physical effects a scene's stages are made of, one module per effect.

>>> sorted(CATALOGUE)
['free_fall', 'impact', 'rise', 'velocity']
"""

from grader.effects.base import Condition, Effect, Field, Relation, Stable
from grader.effects.flight import FREE_FALL, RISE
from grader.effects.impact import IMPACT
from grader.effects.velocity import VELOCITY

CATALOGUE: dict[str, Effect] = {effect.name: effect for effect in (FREE_FALL, RISE, IMPACT, VELOCITY)}

__all__ = ["CATALOGUE", "Condition", "Effect", "Field", "Relation", "Stable"]
