"""Routes where the demonstration's shape runs out: a sampling-based planner (OMPL's RRT-Connect)
over any configuration space with a validity test of one's own, its path shortened, and a
time-optimal timing of a joint path within velocity, acceleration and jerk limits.

Layer 1 (the math): arrays and callables in, arrays out; it knows nothing of scenarios, files or
simulators. The tool's own route through a scene (:func:`tool_route`) is here because it needs only
the scene's geometry; the arm's route (its links against the cell) is :mod:`bidmp.sim.routes`,
which passes this planner a test of the arm's configurations. OMPL and toppra are the extra
``bidmp[plan]``, imported when a route is first planned.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

if TYPE_CHECKING:
    from .rrt import FreeSpace, NoRouteError, Route, plan_route, segment_free
    from .timing import TimedPath, time_path
    from .tool import ToolRoute, tool_route
__getattr__, __dir__ = exports(__name__, __file__, globals())
