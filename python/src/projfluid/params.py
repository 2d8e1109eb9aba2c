"""Simulation parameters: :class:`Params`, a keyword-argument mirror of ``PfParams`` whose
defaults come from the C library (``pf_params_default``) and whose validation is the C
library's (``pf_params_validate``)."""

from __future__ import annotations

import dataclasses
import enum
import operator
from ctypes import byref
from typing import Any

from ._capi import PfParams, lib
from .errors import check


class Solver(enum.IntEnum):
    """``PfSolver``: the global solver run in each outer iteration."""

    CHEBYSHEV = 0
    """One Jacobi sweep plus Chebyshev extrapolation over the outer iterations (default)."""
    JACOBI1 = 1
    """Exactly one Jacobi sweep per outer iteration."""
    JACOBI = 2
    """Jacobi sweeps until the residual drops by 1e-10 or 100 sweeps."""
    CG = 3
    """Conjugate gradients until the residual drops by 1e-10 or 100 iterations."""
    CG1 = 4
    """One conjugate-gradient (steepest-descent) iteration per outer iteration."""
    LDLT = 5
    """Sparse LDLT factorisation once per step, one direct solve per outer iteration."""


class Omega2Rule(enum.IntEnum):
    """``PfOmega2Rule``: how the first Chebyshev weight ω₂ is chosen."""

    CHEBYSHEV = 0
    """ω₂ = 2/(2 − ρ²) (Wang 2015)."""
    PAPER = 1
    """ω₂ = 4/(4 − ρ²), as Sommer et al. (2020) state it (default)."""


class ProjectionWeight(enum.IntEnum):
    """``PfProjectionWeight``: the weight of a particle's share of a local projection."""

    NEIGHBOR_COUNT = 0
    """w = fluid neighbour count + 1 (default)."""
    UNIT = 1
    """w = 1."""
    UNIFORM = 2
    """w = the stencil size at rest density for every particle (experimental)."""


EnumLike = int | str

#: ``Params.backend``'s choices, indexed by their ``PfParams.backend`` value
#: (``PF_BACKEND_CPU``, ``PF_BACKEND_GPU``).
BACKENDS = ("cpu", "gpu")

_C_DEFAULTS = PfParams()
check(lib.pf_params_default(byref(_C_DEFAULTS)))

_UNSIGNED = ("chebyshev_delay", "min_outer_iterations", "max_outer_iterations", "threads")
_ENUMS: dict[str, type[enum.IntEnum]] = {
    "solver": Solver,
    "omega2_rule": Omega2Rule,
    "projection_weight": ProjectionWeight,
}


def _to_enum(kind: type[enum.IntEnum], value: EnumLike, name: str) -> enum.IntEnum:
    """``value`` as a member of ``kind``: a member, its value, or its name in any case."""
    if isinstance(value, str):
        try:
            return kind[value.upper()]
        except KeyError:
            names = ", ".join(m.name.lower() for m in kind)
            raise ValueError(f"{name} must be one of {names}, got {value!r}") from None
    try:
        return kind(value)
    except ValueError:
        raise ValueError(f"{name} must be a {kind.__name__}, got {value!r}") from None


@dataclasses.dataclass(kw_only=True)
class Params:
    """Every setting of a world, in SI units (m, s, kg), with the C library's defaults.

    ``Params(particle_radius=0.02, solver="cg")`` takes keyword arguments only and checks
    them with the C library: a bad value raises
    :class:`~projfluid.errors.InvalidArgumentError` carrying the C status and message, which
    names the field (e.g. ``pf_params_validate: chebyshev_rho must be in [0, 1), got 1.5``).
    A value C cannot represent at all (a negative thread count, an unknown solver name)
    raises :class:`ValueError`; so does a ``backend`` other than ``"cpu"`` and ``"gpu"``.
    ``backend="gpu"`` is checked when a world is made: a library without the GPU backend,
    or a machine without a Vulkan adapter, makes :class:`~projfluid.World` raise
    :class:`~projfluid.errors.InvalidArgumentError` with the library's reason. Note that, as in C, ``displacement_tolerance`` defaults to
    3e-3 times the *default* particle radius: scale it yourself with another radius.
    """

    particle_radius: float = _C_DEFAULTS.particle_radius
    """Particle radius r (m); lattice spacing 2r, support radius 4r."""
    rest_density: float = _C_DEFAULTS.rest_density
    """Rest density ρ0 (kg/m³)."""
    mass_factor: float = _C_DEFAULTS.mass_factor
    """Particle mass as a fraction of ρ0·(2r)³."""
    stiffness: float = _C_DEFAULTS.stiffness
    """Constraint stiffness k (N/m)."""
    gravity: tuple[float, float, float] = tuple(_C_DEFAULTS.gravity)
    """Gravitational acceleration (m/s²)."""
    solver: Solver = Solver(_C_DEFAULTS.solver)
    """The global solver (a :class:`Solver`, its value or its name, e.g. ``"cg"``)."""
    omega2_rule: Omega2Rule = Omega2Rule(_C_DEFAULTS.omega2_rule)
    """Rule for the first Chebyshev weight."""
    chebyshev_rho: float = _C_DEFAULTS.chebyshev_rho
    """Spectral radius estimate ρ_c in [0, 1); only the start value with auto ρ."""
    chebyshev_delay: int = _C_DEFAULTS.chebyshev_delay
    """Outer iterations (≥ 1) before Chebyshev extrapolation starts."""
    chebyshev_gamma: float = _C_DEFAULTS.chebyshev_gamma
    """Under-relaxation γ of the Chebyshev step, in (0, 1]."""
    chebyshev_auto_rho: bool = bool(_C_DEFAULTS.chebyshev_auto_rho)
    """Estimate ρ_c online during the run (True) or use ``chebyshev_rho`` throughout."""
    projection_weight: ProjectionWeight = ProjectionWeight(_C_DEFAULTS.projection_weight)
    """Weighting of the local projection."""
    density_tolerance: float = _C_DEFAULTS.density_tolerance
    """Outer stopping threshold η on the average density error, a fraction in [0, 1): stop
    when the mean of max(ρ/ρ0 − 1, 0) over the fluid is at most η and the last outer iteration
    moved no particle farther than 10 times ``displacement_tolerance`` (0 turns the rule off)."""
    displacement_tolerance: float = _C_DEFAULTS.displacement_tolerance
    """Outer stopping threshold τ (m): stop when no particle moved more than τ."""
    warm_start: float = _C_DEFAULTS.warm_start
    """Share f in [0, 1) of the last step's support a step starts from: particles that
    active constraints moved in the last step start the outer iteration from s + f·Δt²·a,
    a being that step's displacement from its prediction per Δt² (0 starts every step from
    its prediction s, the default). Not used in worlds with bodies; 0 in the calm settings."""
    coarse_correction: bool = bool(_C_DEFAULTS.coarse_correction)
    """Correct the start of every step's outer iteration on a coarse lattice (False, the
    default): the whole fluid moves at once by the displacement that removes its compression
    on cells of two support radii, so that deep water needs far fewer outer iterations. Not
    used in worlds with bodies nor in the calm settings."""
    min_outer_iterations: int = _C_DEFAULTS.min_outer_iterations
    """Smallest number of outer iterations per step (≥ 1)."""
    max_outer_iterations: int = _C_DEFAULTS.max_outer_iterations
    """Largest number of outer iterations per step."""
    cfl_factor: float = _C_DEFAULTS.cfl_factor
    """CFL factor λ in Δt = λ·0.4·2r/v_max."""
    dt_min: float = _C_DEFAULTS.dt_min
    """Smallest CFL step (s)."""
    dt_max: float = _C_DEFAULTS.dt_max
    """Largest CFL step (s)."""
    dt_initial: float = _C_DEFAULTS.dt_initial
    """CFL step size of the first step (s), at most the step over which gravity alone
    moves a particle r/4 (docs/method.md §8)."""
    viscosity: float = _C_DEFAULTS.viscosity
    """XSPH viscosity coefficient in [0, 1] (0 = off)."""
    threads: int = _C_DEFAULTS.threads
    """Worker threads of the world's own pool (0 = one per core)."""
    kinematic_viscosity: float = _C_DEFAULTS.kinematic_viscosity
    """Kinematic viscosity ν (m²/s) of the implicit physical viscosity solve, finite and ≥ 0
    (0 = off, the default): water is 1e-6, olive oil about 1e-4, honey 1e-2 and more. Stable
    at every value and step size; independent of the XSPH ``viscosity``."""
    no_slip: bool = bool(_C_DEFAULTS.no_slip)
    """Under the physical viscosity, the walls, static obstacles and static bodies hold the
    fluid with no slip (True, the default) or let it slide (False, free slip). Moving bodies
    and walls built as fields let it slide either way."""
    backend: str = BACKENDS[_C_DEFAULTS.backend]
    """Where the world's steps run: ``"cpu"`` (the default, double precision) or ``"gpu"``
    (single precision on a Vulkan device, in a library built with the ``gpu`` feature). A
    world on the GPU refuses bodies, walls built as fields, surface tension, wall adhesion
    and solvers other than ``chebyshev`` and ``jacobi1``."""
    vorticity_confinement: float = _C_DEFAULTS.vorticity_confinement
    """Vorticity confinement coefficient ε in [0, 10] (0 = off, the default): gives back
    rotation that the solver and XSPH damp; 0.1–1 is a useful range."""
    surface_tension: float = _C_DEFAULTS.surface_tension
    """Surface tension σ (N/m) of the world's own fluid (material 0), finite and ≥ 0 (0 =
    off, the default, costing nothing): water against air is 0.0728. A world with surface
    tension limits its steps by the capillary rule; the GPU backend refuses it."""
    wall_adhesion: float = _C_DEFAULTS.wall_adhesion
    """Work of adhesion W (N/m) between every fluid and the walls, obstacles and bodies,
    finite and ≥ 0 (0 = off, the default): with a fluid of surface tension σ the contact
    angle θ follows cos θ = W/σ − 1 (W = 2σ wets fully). The GPU backend refuses it."""

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            setattr(self, field.name, _normalized(field.name, getattr(self, field.name)))
        self.validate()

    def validate(self) -> None:
        """Checks every field with ``pf_params_validate``; raises
        :class:`~projfluid.errors.InvalidArgumentError` naming the first bad one."""
        check(lib.pf_params_validate(byref(self.to_c())))

    def calm(self) -> Params:
        """A copy with the calm settings (``pf_params_calm``: uniform weighting, Chebyshev
        at a fixed ρ = 0.99 with γ = 0.5, τ = 3e-4·r, no warm start) under which a settled
        tank stays at rest; every other field is kept."""
        c = self.to_c()
        check(lib.pf_params_calm(byref(c)))
        return Params.from_c(c)

    def to_c(self) -> PfParams:
        """The ``PfParams`` struct for these settings. Raises :class:`ValueError` for a
        value the struct cannot hold (wrong type, negative count, unknown enum name)."""
        c = PfParams()
        for field in dataclasses.fields(self):
            value = _normalized(field.name, getattr(self, field.name))
            if field.name == "backend":
                value = BACKENDS.index(value)
            setattr(c, field.name, int(value) if field.name in _INTEGERS else value)
        return c

    @classmethod
    def from_c(cls, c: PfParams) -> Params:
        """The settings held in a ``PfParams`` struct (validated)."""
        settings = {field.name: getattr(c, field.name) for field in dataclasses.fields(cls)}
        if c.backend < len(BACKENDS):
            settings["backend"] = BACKENDS[c.backend]
        return cls(**settings)


_SWITCHES = ("chebyshev_auto_rho", "coarse_correction", "no_slip")
_INTEGERS = (*_ENUMS, *_UNSIGNED, *_SWITCHES)


def _normalized(name: str, value: Any) -> Any:
    """The field ``name``'s ``value`` in its canonical type, or a :class:`ValueError` naming
    the field when ``PfParams`` cannot hold it."""
    if name in _ENUMS:
        return _to_enum(_ENUMS[name], value, name)
    if name == "backend":
        return _backend(value)
    if name == "gravity":
        return _vector3(value, name)
    if name in _SWITCHES:
        return bool(value)
    if name in _UNSIGNED:
        return _unsigned32(value, name)
    return _real(value, name)


def _backend(value: Any) -> str:
    """``value`` as one of :data:`BACKENDS`, or a :class:`ValueError` naming them."""
    if isinstance(value, str) and value.lower() in BACKENDS:
        return value.lower()
    choices = " or ".join(repr(b) for b in BACKENDS)
    raise ValueError(f"backend must be {choices}, got {value!r}")


def _real(value: Any, name: str) -> float:
    """``value`` as a float, or a :class:`ValueError` naming ``name``."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None


def _unsigned32(value: Any, name: str) -> int:
    """``value`` as an integer that fits a ``uint32_t``, or a :class:`ValueError`."""
    try:
        integer = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer, got {value!r}") from None
    if not 0 <= integer <= 0xFFFF_FFFF:
        raise ValueError(f"{name} must be an integer in 0..4294967295, got {integer}")
    return integer


def _vector3(value: Any, name: str) -> tuple[float, float, float]:
    """``value`` as three floats, or a :class:`ValueError` naming ``name``."""
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be three numbers, got {value!r}") from None
    return (x, y, z)
