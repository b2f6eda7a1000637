from typing import Any, Optional

import numpy.typing as npt

from ._nscdd import RunError as RunError
from ._nscdd import SceneError as SceneError
from ._nscdd import Simulation as Simulation
from ._nscdd import __version__ as __version__

def solve_fc(
    W: Any,
    q: npt.ArrayLike,
    mu: npt.ArrayLike,
    *,
    method: str = "nlgs",
    tol: float = 1e-8,
    max_sweeps: int = 100000,
    norm: str = "natural",
    check_every: int = 1,
    r0: Optional[npt.ArrayLike] = None,
    relaxation: float = 1.0,
) -> dict[str, Any]:
    """Solves u = W r + q under Coulomb's law (W dense or scipy.sparse); returns r, u, sweeps, converged, residual, seconds, norms."""
