"""Result objects: the crate's one representation of each result (its serde form, the JSON the
``hdi`` program prints), as read-only Python objects.

Every key is an attribute, named with its SI unit (``power_w``, ``d_m``, ``time_s``); for a key
ending in ``_w``, ``_m`` or ``_n`` the same value in mW, nm or µN is there too (``power_mw``,
``d_nm``, ``contact_force_un``). Results compare by value (wall-clock times left out), pickle,
and give their plain form back with ``to_dict()``, the JSON of the ``hdi`` program.
"""

from typing import Any, Dict, Iterator, List

# Engineering views of SI keys: suffix asked for -> (SI suffix, factor).
_VIEWS = {"_mw": ("_w", 1e3), "_nm": ("_m", 1e9), "_un": ("_n", 1e6)}


def _plain(v: Any) -> Any:
    if isinstance(v, Result):
        return v.to_dict()
    if isinstance(v, list):
        return [_plain(x) for x in v]
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    return v


def _short(v: Any) -> str:
    if isinstance(v, list) and len(v) > 4:
        return f"[{', '.join(_short(x) for x in v[:2])}, … ({len(v)} items)]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k!r}: {_short(x)}" for k, x in v.items()) + "}"
    return repr(v)


class Result:
    """A result of the crate: its keys as read-only attributes (see the module's docs)."""

    __slots__ = ("_d",)
    #: Keys whose values are results of their own: key -> class.
    _nested: Dict[str, type] = {}

    def __init__(self, data: Dict[str, Any]) -> None:
        d = {}
        for k, v in data.items():
            cls = self._nested.get(k)
            if cls is not None and isinstance(v, dict):
                v = cls(v)
            elif cls is not None and isinstance(v, list):
                v = [cls(x) if isinstance(x, dict) else x for x in v]
            d[k] = v
        object.__setattr__(self, "_d", d)

    def __getattr__(self, name: str) -> Any:
        d = object.__getattribute__(self, "_d")
        if name in d:
            return d[name]
        for view, (si, factor) in _VIEWS.items():
            if name.endswith(view) and name[: -len(view)] + si in d:
                v = d[name[: -len(view)] + si]
                return None if v is None else v * factor
        raise AttributeError(f"{type(self).__name__!r} has no attribute {name!r}")

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._d))

    def keys(self) -> List[str]:
        """The result's keys, as the JSON of the ``hdi`` program names them."""
        return list(self._d)

    def __iter__(self) -> Iterator[str]:
        return iter(self._d)

    def __contains__(self, key: object) -> bool:
        return key in self._d

    def __getitem__(self, key: str) -> Any:
        return self._d[key]

    def to_dict(self) -> Dict[str, Any]:
        """The result as plain Python values: the JSON object the ``hdi`` program prints."""
        return {k: _plain(v) for k, v in self._d.items()}

    def _compared(self) -> Dict[str, Any]:
        return {k: v for k, v in self._d.items() if "wall_seconds" not in k}

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self._compared() == other._compared()  # type: ignore[attr-defined]

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> Any:
        return (type(self), (self.to_dict(),))

    def __repr__(self) -> str:
        parts = ", ".join(f"{k}={_short(v)}" for k, v in self._d.items())
        return f"{type(self).__name__}({parts})"


class Equilibrium(Result):
    """A static equilibrium of the slider: ``d_m``, ``y_m``, ``protrusion_m``, ``power_w``,
    ``stiffness_n_per_m``, ``interface_force_n``, ``contact_force_n``, ``stable`` and ``q`` (every
    coordinate of the structure, one per degree of freedom)."""


class Transition(Result):
    """A touchdown or take-off on the static equilibria: ``power_w``, ``at`` (Equilibrium),
    ``cause`` (``"fold"`` or ``"threshold"``)."""

    _nested = {"at": Equilibrium}


class StaticHysteresis(Result):
    """Static touchdown and take-off: ``scene``, ``touchdown``, ``takeoff`` (Transition),
    ``hysteresis_w``, ``status``, ``flags``."""

    _nested = {"touchdown": Transition, "takeoff": Transition}


class PullIn(Result):
    """The pull-in voltage: ``voltage_v`` (|V − φ|), ``d_m``, ``cause``."""


class Detection(Result):
    """A touchdown or take-off detected in a cycle: ``time_s``, ``power_w``."""


class Cycle(Result):
    """One touchdown/take-off cycle, as ``hdi cycle`` prints it: ``scene``, ``programme``,
    ``v_ac_v``, ``touchdown``/``takeoff`` (Detection or None), ``hysteresis_w``,
    ``mean_temperature_rise_k``, ``duration_s``, ``method`` (as asked, or the stiff method
    ``"auto"`` ran from the start), ``stats``, ``wall_seconds``, ``rtol``,
    ``atol_m``, ``runs``, ``power_change_w``, ``temperature_change_k``, ``total_stats``,
    ``total_wall_seconds``, ``status`` and ``flags``; with an interface lag also ``lag_work_j``
    and ``damping_work_j`` (the lag's energy audit)."""

    _nested = {"touchdown": Detection, "takeoff": Detection}

    @property
    def steps(self) -> int:
        """Accepted solver steps of the run kept (``stats["accepted"]``)."""
        return self._d["stats"]["accepted"]

    @property
    def converged(self) -> bool:
        """Whether ``status`` is ``"converged"``."""
        return self._d["status"] == "converged"


class Mode(Result):
    """One mode of the linearised slider: ``re_per_s``, ``im_per_s`` (the eigenvalue, also as
    the complex ``eigenvalue``), ``frequency_hz``, ``damping_ratio``, ``shape``."""

    @property
    def eigenvalue(self) -> complex:
        """The eigenvalue λ (1/s)."""
        return complex(self._d["re_per_s"], self._d["im_per_s"])


class Calibration(Result):
    """A touchdown calibration as ``hdi calibrate`` prints it: ``scene``, ``detector`` (as
    given), ``detector_name``, ``touchdown_power_w``, ``takeoff_power_w``, ``hysteresis_w``,
    ``set_power_w``, ``clearance_m``, ``contrast``, ``steps``, ``levels``, ``simulated_time_s``,
    ``stats``, ``wall_seconds``, ``status``, ``flags``."""


class Truth(Result):
    """The true values behind one period's sensors, for test oracles: the fields of the Rust
    ``Truth`` and the C ``HdiTruth`` (``gap_nm``, ``pad_gap_nm``, ``displacement_nm``,
    ``velocity_mm_per_s``, ``protrusion_nm``, ``mean_contact_force_un``, ``contact_force_un``,
    ``interface_force_un``, ``mean_flash_temperature_k``, ``friction_power_mw``,
    ``sensor_temperature_k``, ``disk_height_nm``, ``ambient_k``)."""


class Sensors(Result):
    """One controller period's sensors, the fields of the Rust ``Sensors`` and the C
    ``HdiSensors`` in the units their names carry (``time_s``, ``heater_power_mw``,
    ``contact_resistance_ohm``, ``acoustic_v``, ``readback_fundamental_v``,
    ``readback_third_v``), ``hr_clearance_change_nm`` (the harmonic-ratio clearance change
    since the drive's first period) and the true values in ``truth`` (a ``Truth``)."""

    _nested = {"truth": Truth}
