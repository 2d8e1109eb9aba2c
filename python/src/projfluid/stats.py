"""What a step did: :class:`StepStats`, the mirror of ``PfStepStats``."""

from __future__ import annotations

import dataclasses

from ._capi import PfStepStats


@dataclasses.dataclass(frozen=True)
class StepStats:
    """What the last step did, plus the world's counters (``pf_world_last_step_stats``).
    Before the first step ``step_count`` is 0 and the per-step fields are 0."""

    step_count: int
    """Steps taken so far."""
    time: float
    """Simulated time after the last step (s)."""
    dt: float
    """Size of the last step (s)."""
    outer_iterations: int
    """Outer (local/global) iterations of the last step."""
    inner_iterations: int
    """Linear-solver iterations of the last step, summed over its outer iterations."""
    hit_max_iterations: bool
    """The last step stopped at ``max_outer_iterations`` instead of the displacement rule."""
    last_displacement: float
    """Largest particle displacement in the last outer iteration of the last step (m)."""
    density_error_avg_percent: float
    """Mean compression max(ρ/ρ0 − 1, 0) over the fluid after the last step (per cent)."""
    density_error_max_percent: float
    """Largest compression of any fluid particle after the last step (per cent)."""
    escaped_count: int
    """Fluid particles farther than r/2 outside every container."""
    nan_count: int
    """Fluid particles with a non-finite position or velocity."""

    @classmethod
    def from_c(cls, c: PfStepStats) -> StepStats:
        """The statistics held in a ``PfStepStats`` struct."""
        return cls(**{field.name: getattr(c, field.name) for field in dataclasses.fields(cls)})
