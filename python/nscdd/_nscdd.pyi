"""Type stubs of nscdd's Rust extension (docs/PYTHON.md)."""

from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class SceneError(ValueError):
    """A scene that cannot be loaded; the message names the file, line and key."""

class RunError(RuntimeError):
    """A run that stopped: a diverging body (step and body named), an output that cannot be written, a finished run stepped."""

SceneSource = Union[str, "PathLike[str]", dict[str, Any]]

class Simulation:
    """A loaded scene and its run.

    scene: a TOML scene file's path, or a dict of the same keys (lists of tables as
    lists of dicts; None leaves a key out). out: the folder for the outputs of
    `nscdd run` (history.csv, VTK frames, checkpoints, final.json), or None to write
    nothing. restart: a saved state (final.json, checkpoint.json, save()) to
    continue bitwise.
    """

    def __init__(self, scene: SceneSource, out: Optional[Union[str, "PathLike[str]"]] = None, restart: Optional[Union[str, "PathLike[str]"]] = None) -> None: ...
    @staticmethod
    def from_toml(text: str, out: Optional[Union[str, "PathLike[str]"]] = None, restart: Optional[Union[str, "PathLike[str]"]] = None) -> "Simulation":
        """A simulation from the text of a TOML scene."""
    @property
    def dimension(self) -> int:
        """2 or 3."""
    @property
    def current_step(self) -> int:
        """Steps done (a restart continues its count)."""
    @property
    def total_steps(self) -> int:
        """The scene's last step ([time] steps, moved by run(n) past it)."""
    @property
    def time(self) -> float: ...
    @property
    def n_bodies(self) -> int: ...
    @property
    def gravity(self) -> list[float]:
        """The gravity vector (m/s²)."""
    @gravity.setter
    def gravity(self, g: "Sequence[float]") -> None:
        """Between steps (scenes without deformable bodies or continuum regions)."""
    @property
    def finished(self) -> bool:
        """Whether finish() was called."""
    def step(self) -> dict[str, Any]:
        """One step; its report: step, time, contacts, sweeps, converged, residual."""
    def run(
        self,
        steps: Optional[int] = None,
        *,
        callback: Optional[Callable[["Simulation"], Any]] = None,
        every: int = 1,
        progress: bool = True,
    ) -> dict[str, Any]:
        """Runs `steps` more steps (None: to the scene's end, then finish()), the GIL
        released; callback(sim) every `every` steps; a tqdm bar when installed.
        Ctrl-C stops after the step, writes checkpoint.json (with `out`) and raises
        KeyboardInterrupt. Returns the summary: steps, total_sweeps,
        unconverged_steps, first_unconverged, suspect_steps, max_residual,
        wall_seconds."""
    def finish(self) -> dict[str, Any]:
        """Ends the run (a last frame, the VTK series and final.json with `out`); its summary."""
    def save(self, path: Union[str, "PathLike[str]"]) -> None:
        """Writes the state as a restart file."""
    def positions(self, copy: bool = True) -> npt.NDArray[np.float64]:
        """(n, dim) body positions: a copy, or with copy=False a read-only live view
        of the simulation's array (the state after the last step, at every step)."""
    def velocities(self, copy: bool = True) -> npt.NDArray[np.float64]:
        """(n, dim) translational velocities (copy=False: a live view)."""
    def angular_velocities(self, copy: bool = True) -> npt.NDArray[np.float64]:
        """(n,) in 2D, (n, 3) in 3D (copy=False: a live view)."""
    def rotations(self) -> npt.NDArray[np.float64]:
        """The angle (n,) in 2D, rotation vectors (n, 3) in 3D."""
    def radii(self) -> npt.NDArray[np.float64]:
        """(n,) radii of balls, the size of other shapes."""
    def shapes(self) -> dict[str, Any]:
        """kinds (the shape kinds' names), kind (n,) each body's index in them, shape (n,) its id within the kind."""
    def masses(self) -> npt.NDArray[np.float64]:
        """(n,) masses (2D: per unit depth)."""
    def names(self) -> list[Optional[str]]: ...
    def body(self, name: str) -> int:
        """The index of the body named `name`."""
    def contacts(self) -> dict[str, npt.NDArray[Any]]:
        """The last step's contacts: bodies (m, 2), point, normal, r (local impulse,
        normal first), impulse (world frame) (m, dim), gap (m,), bonded (m,)."""
    def subdomains(self) -> Optional[dict[str, npt.NDArray[Any]]]:
        """With NSCDD (a decomposition or body families), after a step: bodies (n,)
        each body's subdomain (−1: no contacts), copies (n,), contacts (m,) each
        contact's subdomain; else None."""
    def history(self, as_frame: bool = False) -> Any:
        """history.csv's columns as a dict of arrays (as_frame: a pandas DataFrame)."""
    def set_drive(self, body: Union[int, str], dof: str, drive: Union[dict[str, Any], list[dict[str, Any]]]) -> None:
        """Changes the drive of a driven body's degree of freedom ("x", "y", "rot";
        3D "x", "y", "z", "rx", "ry", "rz") in the scene's syntax."""

def _solve_fc_coo(
    rows: npt.NDArray[np.int64],
    cols: npt.NDArray[np.int64],
    vals: npt.NDArray[np.float64],
    q: npt.NDArray[np.float64],
    mu: npt.NDArray[np.float64],
    *,
    method: str = "nlgs",
    tol: float = 1e-8,
    max_sweeps: int = 100000,
    norm: str = "natural",
    check_every: int = 1,
    relaxation: float = 1.0,
    r0: Optional[npt.NDArray[np.float64]] = None,
) -> dict[str, Any]: ...
