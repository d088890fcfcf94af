"""The catalogue of physical effects a scene's stages are made of, one module per effect.

>>> print(*sorted(CATALOGUE)[:8])
angle_between bounces flight free_fall impact impact_geometry impulse rise
>>> print(*sorted(CATALOGUE)[8:])
separation slide slope spring stick swing velocity
"""

from grader.physics.effects.base import Condition, Effect, Field, Mistake, Relation, Route, Stable
from grader.physics.effects.bounces import BOUNCES
from grader.physics.effects.flight import FREE_FALL, RISE
from grader.physics.effects.geometry import IMPACT_GEOMETRY
from grader.physics.effects.impact import IMPACT
from grader.physics.effects.impulse import IMPULSE_EFFECT
from grader.physics.effects.projectile import FLIGHT
from grader.physics.effects.separation import SEPARATION
from grader.physics.effects.slide import SLIDE
from grader.physics.effects.slope import SLOPE
from grader.physics.effects.spring import SPRING
from grader.physics.effects.stick import STICK
from grader.physics.effects.swing import SWING
from grader.physics.effects.velocity import ANGLE_BETWEEN, VELOCITY

CATALOGUE: dict[str, Effect] = {effect.name: effect for effect in (FREE_FALL, RISE, IMPACT_GEOMETRY, IMPACT, VELOCITY,
                                                                   ANGLE_BETWEEN, BOUNCES, SWING, SLIDE, FLIGHT,
                                                                   SPRING, SLOPE, STICK, IMPULSE_EFFECT,
                                                                   SEPARATION)}

__all__ = ["CATALOGUE", "Condition", "Effect", "Field", "Mistake", "Relation", "Route", "Stable"]
