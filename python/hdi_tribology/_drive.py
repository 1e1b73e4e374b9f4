"""The simulated drive: the native drive, kept to the thread that made it."""

import threading
from typing import Any, Dict, List, Optional, Sequence, Union

from . import _core
from ._results import Sensors


class Drive:
    """A simulated drive for firmware prototyping: the scene's slider flying over a disk with
    run-out and waviness (or a flat one), with a heater, a head–disk voltage and the sensors
    firmware reads, stepped at the controller's rate (``docs/clearance.md``).

    The drive is the scene's ``[drive]`` section (docs/scene_format.md), with the keyword
    ``settings`` over it, each in the unit its name carries: ``radius_mm``, ``rpm``,
    ``initial_heater_power_mw`` (the start: at rest in the flying equilibrium there),
    ``heater_time_constant_us``, ``runout_nm``, ``waviness_rms_nm``, ``waviness_orders``
    (``(lowest, highest)``), ``ambient_rate_k_per_s``, ``ambient_amplitude_k``,
    ``ambient_period_s``, ``ambient_clearance_per_kelvin_nm``, ``ambient_step_k``,
    ``ambient_step_time_s``, ``ae_gain_v_per_sqrt_w``, ``ae_bandwidth_khz``, ``ae_noise_v``,
    ``contact_noise_ohm``, ``readback_wavelength_nm`` (``heads`` must be 1: one ``Drive`` is
    one head; ``MultiDrive`` steps several), and ``steps_per_period`` (the bounded mode for
    firmware in the loop: at most that many Radau5 steps a period, a step at the bound
    accepted whatever its error; ``last_period`` gives the flag; docs/clearance.md, "The
    bounded mode"), and ``scheme`` (``"integrator"``, the default, or ``"exponential"``: one
    exponential step a period with the Jacobian held, the integrator where it misses, which
    ``last_period["exponential"]`` tells; docs/clearance.md, "The exponential scheme").
    ``flat_disk`` drops the run-out and waviness. ``atol_pm`` (default 0.01) and
    ``atol_flight_pm`` (default ``atol_pm``, at least ``atol_pm``) are the integration's
    displacement tolerances near contact and in flight (pm). The same seed gives the same disk
    and the same sensor noise, bit for bit; stepping it with the commands of a command file
    gives the rows ``replay`` (and ``hdi drive``) gives. A bad setting raises
    ``InvalidInputError`` naming it, with the value in its unit.

    A ``Drive`` belongs to the thread that made it: a call from another thread raises
    ``RuntimeError`` (make one drive per thread; ``replay`` may run on any thread).
    """

    __slots__ = ("_core", "_thread")

    def __init__(self, scene: Union["_core.Scene", "_core.Model"], *, seed: int = 1,
                 flat_disk: bool = False, atol_pm: Optional[float] = None,
                 atol_flight_pm: Optional[float] = None, **settings: Any) -> None:
        self._thread = threading.get_ident()
        self._core = _core.Drive(scene, seed=seed, flat_disk=flat_disk, atol_pm=atol_pm,
                                 atol_flight_pm=atol_flight_pm, **settings)

    def _native(self) -> Any:
        if threading.get_ident() != self._thread:
            raise RuntimeError(
                "a Drive belongs to the thread that made it: make one Drive per thread")
        return self._core

    def step(self, heater_power_mw: float, *, dc_voltage_v: float = 0.0,
             ac_amplitude_v: float = 0.0, ac_frequency_khz: float = 0.0,
             period_s: float = 50e-6) -> Sensors:
        """Holds the command (the names of the Rust ``Command`` and the C ``HdiCommand``):
        heater power ``heater_power_mw`` (mW), DC voltage ``dc_voltage_v`` (V), AC dither
        ``ac_amplitude_v`` (V) at ``ac_frequency_khz`` (kHz), for one period of ``period_s``
        (s); returns the ``Sensors`` at its end (the fields of the C ``HdiSensors``)."""
        return self._native().step(heater_power_mw, dc_voltage_v=dc_voltage_v,
                                   ac_amplitude_v=ac_amplitude_v,
                                   ac_frequency_khz=ac_frequency_khz, period_s=period_s)

    @property
    def time_s(self) -> float:
        """Simulated time so far (s)."""
        return self._native().time_s

    @property
    def term_states(self) -> List[float]:
        """The states of the model's terms with memory at the drive's time."""
        return self._native().term_states

    @property
    def stats(self) -> Dict[str, int]:
        """Integrator work so far: accepted, rejected, rhs_evals, jac_evals, lu_decomps, …"""
        return self._native().stats

    @property
    def seed(self) -> int:
        """Seed of the disk's random waviness and of the sensor noise."""
        return self._native().seed

    @property
    def last_period(self) -> Dict[str, Any]:
        """How the last period was advanced: ``steps`` (ended in it) and ``error_estimate``
        (the weighted error estimate against the tolerances: at most 1 under adaptive control;
        in the bounded mode, above 1 where a step missed them)."""
        return self._native().last_period

    def __repr__(self) -> str:
        name, radius_mm = self._native().zone
        return (f"Drive(scene={name!r}, seed={self.seed}, radius_mm={radius_mm}, "
                f"time_s={self.time_s})")


Number = Union[float, Sequence[float]]


class MultiDrive:
    """A drive of several heads on one disk: one spindle and one clock, each head its own
    slider, heater, sensors and surface (its own run-out and random waviness), stepped together
    (``docs/firmware.md``, "Several heads").

    ``scene`` is one ``Scene`` (or ``Model``) for every head, with ``heads=N`` among the
    keyword ``settings`` (those of ``Drive``) or the scene's ``[drive] heads``; or a list of
    scenes, one per head, each head its own slider at the first scene's radius and spindle
    speed. Head ``k`` is seeded ``head_seed(seed, k)`` (head 0 by ``seed`` itself): its sensors
    are, to the bit, those of a one-head ``Drive`` of its scene and seed given the same
    commands; the heads do not interact. A bad setting raises ``InvalidInputError`` naming it.

    A ``MultiDrive`` belongs to the thread that made it, as a ``Drive`` does.
    """

    __slots__ = ("_core", "_thread")

    def __init__(self, scene: Union["_core.Scene", "_core.Model", Sequence["_core.Scene"]], *,
                 seed: int = 1, flat_disk: bool = False, atol_pm: Optional[float] = None,
                 atol_flight_pm: Optional[float] = None, **settings: Any) -> None:
        self._thread = threading.get_ident()
        self._core = _core.MultiDrive(scene, seed=seed, flat_disk=flat_disk, atol_pm=atol_pm,
                                      atol_flight_pm=atol_flight_pm, **settings)

    def _native(self) -> Any:
        if threading.get_ident() != self._thread:
            raise RuntimeError(
                "a MultiDrive belongs to the thread that made it: make one per thread")
        return self._core

    def step(self, heater_power_mw: Number, *, dc_voltage_v: Optional[Number] = None,
             ac_amplitude_v: Optional[Number] = None, ac_frequency_khz: Optional[Number] = None,
             period_s: float = 50e-6) -> List[Sensors]:
        """Holds each head's command for one period of ``period_s`` (s) and returns the heads'
        ``Sensors`` in head order. Each of ``heater_power_mw`` (mW), ``dc_voltage_v`` (V),
        ``ac_amplitude_v`` (V) and ``ac_frequency_khz`` (kHz) is a number for every head or a
        sequence of one per head (default 0). Every command is checked before any head moves;
        an error names the argument and the head (``heater_power_mw[1]``)."""
        return self._native().step(heater_power_mw, dc_voltage_v=dc_voltage_v,
                                   ac_amplitude_v=ac_amplitude_v,
                                   ac_frequency_khz=ac_frequency_khz, period_s=period_s)

    @property
    def heads(self) -> int:
        """The number of heads."""
        return self._native().heads

    @property
    def time_s(self) -> float:
        """Simulated time so far (s): one clock for every head."""
        return self._native().time_s

    @property
    def seeds(self) -> List[int]:
        """Each head's seed (its surface and sensor noise)."""
        return self._native().seeds

    def __repr__(self) -> str:
        return f"MultiDrive(heads={self.heads}, time_s={self.time_s})"
