"""``mp-dmp``: movement_primitives' DMP (a peer library, in the ``test``/``bench`` extras), with
its defaults and 50 weights per dimension, over the demonstration's own time."""

from __future__ import annotations

import numpy as np

from ..._checks import as_point
from .base import Method, Task


class _PeerDMP(Method):
    name = "mp-dmp"
    requires = "movement_primitives"

    def fit(self, task: Task) -> tuple[object, float]:
        def build():
            from movement_primitives.dmp import DMP

            y = task.demonstration
            t = np.linspace(0.0, 1.0, len(y))
            peer = DMP(n_dims=y.shape[1], execution_time=1.0, dt=t[1], n_weights_per_dim=50)
            peer.imitate(t, y)
            return peer, y[0]

        return task.shared_model("mp-dmp", build)

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        if not (isinstance(model, tuple) and len(model) == 2 and hasattr(model[0], "open_loop")):
            raise TypeError(
                f"model must be (a movement_primitives DMP, start), what method 'mp-dmp''s fit returns, "
                f"got {type(model).__name__}"
            )
        peer, start = model
        goal = as_point(goal, len(start), "goal")
        peer.configure(start_y=start, goal_y=goal)
        return peer.open_loop()[1]


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (_PeerDMP(),)
