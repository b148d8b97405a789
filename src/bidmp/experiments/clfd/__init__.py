"""Continual learning from demonstration on the field's own protocol (CLFD: Auddy, Hollenstein,
Saveriano, Rodríguez-Sánchez, Piater, Robotics and Autonomous Systems 2023).

Tasks arrive one at a time in the protocol's order (LASA: 26 shapes, 7 demonstrations each, raw
LASA units). After learning task i, every task j ≤ i is evaluated: each of its demonstrations is
reproduced from that demonstration's own start, on the first demonstration's time vector, and
compared with the demonstration by

* **DTW**: Euclidean point distances accumulated along the optimal warping path, not normalised
  (:func:`bidmp.extension.dtw_distance`);
* **discrete Fréchet** distance (:func:`bidmp.extension.frechet_distance`);
* **swept error area**: the areas of the quadrilaterals between corresponding points
  (:func:`swept_error_area`, the LASA benchmark's).

Entry (i, j) of a metric's accuracy matrix is the fraction of task j's demonstrations whose error
is within the protocol's threshold (LASA: DTW 2191, Fréchet 5.0, swept area 70.0). From the
lower-triangular matrix A of N tasks (:func:`continual_metrics`): ACC = Σ_{j≤i} A[i, j] /
(N (N + 1) / 2); BWT = the mean over j < i of A[i, j] − A[j, j]; REM = 1 − |min(BWT, 0)|; MS =
min(1, the mean over i of size(after task 0) / size(after task i)) — a library that grows by one
equal block per task scores H_N / N; TE = min(1, the mean over i of time(task 0) / time(task i));
FS = 1 − size / the largest size compared. CL_score is the mean of ACC, REM, MS, TE and FS;
CL_stability 1 − their standard deviation (ddof 1).

RoboTasks9 (9 pose tasks, 9 demonstrations each) adds the orientation error ‖2 · log(q_true ⊗
q̄_pred)‖ averaged over time (:func:`orientation_error`); its position metrics are DTW and
Fréchet. A pose is learned as a curve in the tangent space of the unit sphere at the task's first
start orientation (:class:`TangentChart`).

The methods (``METHODS``) learn a task from its demonstrations and reproduce any task seen:
``dmp-library`` keeps one DMP per task (:class:`DMPLibrary`), ``finetune`` one DMP refitted on
each (:class:`FineTune`), ``bidmp-library`` one Bi-DMP learning each task as a new skill
(:class:`BiDMPLibrary`), ``promp-library`` one ProMP per task (:class:`ProMPLibrary`);
``bidmp-continual`` is a ridge memory of each task's start map of a fixed size, one BLS that
gives the task's map from the task's code (:class:`ContinualBLS`); ``map-library`` keeps the same
maps as they are (:class:`MapLibrary`, the yardstick of its capacity sweep, ``capacity``).

Parts: ``data`` (the tasks, the chart), ``metrics`` (errors and figures), ``methods`` (the rows),
``protocol`` (the runner, its cells on Dask, the files), ``capacity`` (``bidmp-continual``'s
node counts against the map library).
"""

from .capacity import (
    CAPACITY_NODES,
    CapacityResult,
    CapacityRow,
    capacity_sweep,
    write_capacity,
)
from .data import CLFD_DATASETS, ClfdTask, TangentChart, clfd_tasks
from .methods import (
    METHODS,
    BiDMPLibrary,
    ClfdMethod,
    ContinualBLS,
    DMPLibrary,
    FineTune,
    MapLibrary,
    ProMPLibrary,
)
from .metrics import (
    CLFD_THRESHOLDS,
    accuracy_matrix,
    continual_metrics,
    demonstration_errors,
    orientation_error,
    swept_error_area,
)
from .protocol import (
    PUBLISHED_BEST,
    PUBLISHED_BEST_MEAN_DTW,
    PUBLISHED_HYPERNETWORK_PARAMETERS,
    ClfdResult,
    ClfdRow,
    run_clfd,
    write_clfd,
)

__all__ = [
    "CAPACITY_NODES",
    "CLFD_DATASETS",
    "CLFD_THRESHOLDS",
    "METHODS",
    "BiDMPLibrary",
    "CapacityResult",
    "CapacityRow",
    "ClfdMethod",
    "ClfdResult",
    "ClfdRow",
    "ClfdTask",
    "ContinualBLS",
    "DMPLibrary",
    "FineTune",
    "MapLibrary",
    "ProMPLibrary",
    "TangentChart",
    "accuracy_matrix",
    "capacity_sweep",
    "clfd_tasks",
    "continual_metrics",
    "demonstration_errors",
    "orientation_error",
    "run_clfd",
    "swept_error_area",
    "write_capacity",
    "write_clfd",
]
