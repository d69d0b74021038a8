"""Types of the native module: the Rust API of chetaev, as the Python package sees it.

Conventions (docs/conventions.md): Chetaev's equations in Newton form,
``d/dt ∂L/∂q̇ − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇ + Q``; the Chetaev force ``Φ = Σ_a μ_a ∂f_a/∂q̇``; the
energy ``E = q̇·∂L/∂q̇ − L`` with ``dE/dt = q̇·Φ + q̇·Q − ∂L/∂t``.
"""

from os import PathLike
from typing import Any, Literal, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Array = npt.Array
Direction = Literal["either", "rising", "falling"]

class ChetaevError(ValueError):
    """Bad input: a model, problem or option chetaev cannot use; the message says what to try."""

class SceneError(ChetaevError):
    """A scene that cannot be read; the message gives the line and column."""

class Model:
    """``L(t, q, q̇)``, velocity constraints ``f``, holonomic constraints ``h``, forces ``Q`` and a
    Rayleigh function ``D`` as one expression graph with shared subexpressions."""

    def __init__(
        self,
        n: int,
        ops: Sequence[tuple[str, Sequence[int], float]],
        lagrangian: int,
        constraints: Sequence[int] = ...,
        holonomic: Sequence[int] = ...,
        forces: Sequence[int] = ...,
        dissipation: Optional[int] = None,
        parameters: Sequence[tuple[str, float]] = ...,
        coordinates: Optional[Sequence[str]] = None,
        symbols: Any = None,
    ) -> None: ...
    @classmethod
    def from_sympy(
        cls,
        lagrangian: Any = None,
        q: Sequence[Any] = (),
        *,
        constraints: Sequence[Any] = (),
        holonomic: Sequence[Any] = (),
        forces: Optional[Sequence[Any]] = None,
        loads: Optional[Sequence[tuple[Any, Any]]] = None,
        frame: Any = None,
        bodies: Optional[Sequence[Any]] = None,
        rayleigh: Any = None,
        parameters: Optional[Mapping[Any, float]] = None,
        t: Any = None,
    ) -> "Model": ...
    @property
    def n(self) -> int: ...
    @property
    def k(self) -> int:
        """The number of velocity constraints."""
    @property
    def holonomic_count(self) -> int: ...
    @property
    def coordinates(self) -> list[str]: ...
    @property
    def parameters(self) -> list[tuple[str, float]]: ...
    @property
    def operations(self) -> int: ...
    @property
    def symbols(self) -> Any: ...
    def with_parameters(self, values: Mapping[Any, float]) -> "Model": ...
    def __reduce__(self) -> Any:
        """Pickled as its operations and parameter values."""

class Description:
    """What the library derived; ``str()`` is text, Jupyter renders ``_repr_latex_``."""

    @property
    def latex(self) -> str: ...
    def _repr_latex_(self) -> Optional[str]: ...

class Problem:
    """A model with a checked initial state ``(t0, q0, q̇0)``."""

    def __init__(
        self,
        model: Model,
        q0: Union[Sequence[float], Array, Mapping[Any, float]],
        qd0: Union[Sequence[float], Array, Mapping[Any, float]],
        t0: float = 0.0,
        project_velocity: bool = False,
        route: Literal["graph", "dual"] = "graph",
        independent_coordinates: Optional[Sequence[Any]] = None,
        independent_speeds: Optional[Sequence[Any]] = None,
        complete: bool = False,
        machine_code: Literal["auto", "never", "at_once"] = "auto",
    ) -> None:
        """Naming independent coordinates or speeds (or ``complete=True``) solves the dependent
        ones from the constraints first (see ``complete``). ``project_velocity=True`` makes the
        state consistent: it projects the position onto the holonomic constraints ``h = 0``, then
        the velocity onto the velocity constraints and ``ḣ = 0``. ``machine_code``: when the
        right-hand side runs as machine code: ``"auto"`` when the right-hand sides still expected
        pay for compiling it (solves repeat themselves to the bit), ``"never"``, or ``"at_once"``
        (compiled before the first solve)."""
    @property
    def model(self) -> Optional[Model]: ...
    @property
    def coordinates(self) -> list[str]: ...
    @property
    def t0(self) -> float: ...
    @property
    def q0(self) -> Array: ...
    @property
    def qd0(self) -> Array: ...
    @property
    def sizes(self) -> tuple[int, int]:
        """``(n, k)``: coordinates, multipliers (velocity plus holonomic constraints)."""
    def equations_at(
        self, t: float, q: Sequence[float], qd: Sequence[float]
    ) -> dict[str, Any]: ...
    def describe(
        self,
        t: Optional[float] = None,
        q: Optional[Sequence[float]] = None,
        qd: Optional[Sequence[float]] = None,
    ) -> Description: ...
    def linearize(
        self,
        t: Optional[float] = None,
        q: Optional[Sequence[float]] = None,
        qd: Optional[Sequence[float]] = None,
        coordinates: Optional[Sequence[Any]] = None,
        speeds: Optional[Sequence[Any]] = None,
    ) -> "Linearization":
        """The reduced equations linearised on the constraint manifold at a state (the initial
        one by default), in independent coordinates and speeds (chosen by pivoting where None)."""

class Linearization:
    """``δż = A δz`` in the independent coordinates and speeds ``z`` (named by ``states``)."""

    @property
    def a(self) -> Array: ...
    @property
    def eigenvalues(self) -> npt.NDArray[np.complex128]: ...
    @property
    def eigenvectors(self) -> npt.NDArray[np.complex128]:
        """One column per eigenvalue, unit length."""
    @property
    def states(self) -> list[str]: ...
    @property
    def coordinates(self) -> list[int]: ...
    @property
    def speeds(self) -> list[int]: ...
    @property
    def cyclic(self) -> list[str]:
        """Coordinates nothing depends on: each gives an eigenvalue exactly 0."""
    @property
    def full(self) -> Array: ...
    @property
    def basis(self) -> Array: ...

def complete(
    model: Model,
    q: Union[Sequence[float], Array, Mapping[Any, float]],
    qd: Union[Sequence[float], Array, Mapping[Any, float]],
    t: float = 0.0,
    coordinates: Optional[Sequence[Any]] = None,
    speeds: Optional[Sequence[Any]] = None,
) -> tuple[Array, Array]:
    """The dependent coordinates from ``h = 0`` and speeds from ``f = 0``, ``ḣ = 0``, by Newton's
    method from the values given, the independent ones (named, or chosen by pivoting) held."""

class Event:
    """The zeros of ``g(t, q, q̇)`` (a sympy expression, or a string in the coordinates' names with
    ``x_dot`` for ẋ), counted in ``direction``; a terminal event ends the run."""

    name: str
    expression: Any
    direction: Direction
    terminal: bool
    def __init__(
        self, name: str, expression: Any, direction: Direction = "either", terminal: bool = False
    ) -> None: ...

class EventHit:
    index: int
    name: str
    t: float
    q: Array
    qd: Array
    dt: dict[str, float]
    """``∂t/∂θ`` for each seed."""

class Seed:
    """A direction in the parameters and initial values for sensitivities."""

    def __init__(
        self,
        name: str,
        parameters: Optional[Mapping[Any, float]] = None,
        positions: Optional[Sequence[tuple[int, float]]] = None,
        velocities: Optional[Sequence[tuple[int, float]]] = None,
    ) -> None: ...
    @staticmethod
    def parameter(name: Any) -> "Seed": ...
    @staticmethod
    def position(i: int) -> "Seed": ...
    @staticmethod
    def velocity(i: int) -> "Seed": ...
    @property
    def name(self) -> str: ...

class Solution:
    """The motion and what was recorded along it, one row per recorded point."""

    method: str
    t: Array
    q: Array
    qd: Array
    qdd: Array
    mu: Array
    phi: Array
    residual: Array
    relative_residual: Array
    position_residual: Array
    energy: Array
    work: Array
    dl_dt_integral: Array
    work_forces: Array
    energy_balance: Array
    events: list[EventHit]
    sensitivities: Optional[dict[str, dict[str, Array]]]
    stats: dict[str, int]
    status: Literal["success", "terminated", "failed"]
    warnings: list[str]
    terminated_by: Optional[int]
    message: Optional[str]
    success: bool
    n: int
    k: int
    def __len__(self) -> int: ...

class Scene:
    """A scene file (docs/scenes.md)."""

    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "Scene": ...
    @staticmethod
    def parse(text: str, name: str = "<scene>") -> "Scene": ...
    def solve(self) -> Solution: ...
    def problem(self) -> Problem: ...
    def describe(self, latex: bool = False) -> str: ...
    @property
    def coordinates(self) -> list[str]: ...
    @property
    def warnings(self) -> list[str]:
        """What is valid but may not be what was meant (an ``e`` read as Euler's number), each
        as ``path:line:column: message``, in the order of the file."""
    def sweep(
        self,
        vary: Optional[Mapping[str, Union[str, float, Sequence[float], Mapping[str, Any]]]] = None,
        *,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        design: Optional[str] = None,
        collect: Optional[Sequence[str]] = None,
        shard: Optional[str] = None,
        jobs: Optional[int] = None,
        yes: bool = False,
    ) -> "SweepTable":
        """The scene over a grid or a random sample of its parameters and initial values, in
        parallel (docs/sweeps.md)."""

class SweepTable:
    """The runs of a sweep: variables, status, quantities, reasons; ``table["impact.t"]``."""

    @property
    def variables(self) -> list[str]: ...
    @property
    def columns(self) -> list[str]: ...
    @property
    def index(self) -> npt.NDArray[np.uint64]: ...
    @property
    def values(self) -> Array: ...
    @property
    def quantities(self) -> Array: ...
    @property
    def status(self) -> list[str]: ...
    @property
    def reason(self) -> list[str]: ...
    @property
    def steps(self) -> npt.NDArray[np.uint64]: ...
    def counts(self) -> tuple[int, int, int]: ...
    def __getitem__(self, name: str) -> Array: ...
    def __len__(self) -> int: ...
    def to_csv(self) -> str: ...
    def write(self, directory: Union[str, PathLike[str]]) -> list[str]: ...

def merge_sweeps(files: Sequence[Union[str, PathLike[str]]]) -> SweepTable:
    """Joins the part files of a sharded sweep into the whole sweep's table."""

def solve(
    problem: Problem,
    t_end: float,
    method: str = "dop853",
    rtol: Optional[float] = None,
    atol: Union[None, float, Sequence[float]] = None,
    step: Optional[float] = None,
    output: Union[None, Literal["steps", "final"], Sequence[float], Array] = None,
    record: Literal["state", "dynamics", "energy"] = "energy",
    events: Sequence[Event] = (),
    project: Union[None, bool, float] = None,
    max_step: Optional[float] = None,
    initial_step: Optional[float] = None,
    max_steps: Optional[int] = None,
    event_samples: Optional[int] = None,
    sensitivities: Sequence[Union[str, Any, Seed]] = (),
    sensitivity_control: bool = False,
    stiffness_detection: Optional[bool] = None,
    controller: Optional[Mapping[str, float]] = None,
    rank_tolerance: Optional[float] = None,
) -> Solution: ...
def methods() -> list[str]: ...
