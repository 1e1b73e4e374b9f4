"""The simulated drive: the native drive, kept to the thread that made it."""

import threading
from typing import Any, Dict, List, Optional, Union

from . import _core
from ._results import Sensors


class Drive:
    """A simulated drive for firmware prototyping: the scene's slider flying over a disk with
    run-out and waviness (or a flat one), with a heater, a head–disk voltage and the sensors
    firmware reads, stepped at the controller's rate (``docs/clearance.md``).

    Starts at rest in the flying equilibrium at ``initial_power_mw``. ``atol_pm`` (default
    0.01) and ``atol_flight_pm`` (default ``atol_pm``, at least ``atol_pm``) are the
    integration's displacement tolerances near contact and in flight (pm). The same seed gives
    the same disk and the same sensor noise, bit for bit; stepping it with the commands of a
    command file gives the rows ``replay`` (and ``hdi drive``) gives.

    A ``Drive`` belongs to the thread that made it: a call from another thread raises
    ``RuntimeError`` (make one drive per thread; ``replay`` may run on any thread).
    """

    __slots__ = ("_core", "_thread")

    def __init__(self, scene: Union["_core.Scene", "_core.Model"], *, seed: int = 1,
                 radius_mm: float = 25.0, flat_disk: bool = False,
                 initial_power_mw: float = 60.0, atol_pm: Optional[float] = None,
                 atol_flight_pm: Optional[float] = None) -> None:
        self._thread = threading.get_ident()
        self._core = _core.Drive(scene, seed=seed, radius_mm=radius_mm, flat_disk=flat_disk,
                                 initial_power_mw=initial_power_mw, atol_pm=atol_pm,
                                 atol_flight_pm=atol_flight_pm)

    def _native(self) -> Any:
        if threading.get_ident() != self._thread:
            raise RuntimeError(
                "a Drive belongs to the thread that made it: make one Drive per thread")
        return self._core

    def step(self, heater_mw: float, *, dc_v: float = 0.0, ac_v: float = 0.0,
             ac_khz: float = 0.0, dt_us: float = 50.0) -> Sensors:
        """Holds the heater at ``heater_mw`` (mW) and the voltage at ``dc_v`` (V) plus an AC
        dither of ``ac_v`` (V) at ``ac_khz`` (kHz) for one period of ``dt_us`` (µs); returns
        the sensors at its end: the columns of ``SENSOR_COLUMNS``, as ``replay`` gives them."""
        return self._native().step(heater_mw, dc_v=dc_v, ac_v=ac_v, ac_khz=ac_khz, dt_us=dt_us)

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

    def __repr__(self) -> str:
        name, radius_mm = self._native().zone
        return (f"Drive(scene={name!r}, seed={self.seed}, radius_mm={radius_mm}, "
                f"time_s={self.time_s})")
