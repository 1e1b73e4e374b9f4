"""Type stubs of the native core. Units are in every name: ``_m``, ``_w``, ``_n``, ``_s``,
``_k`` (SI) and ``_nm``, ``_mw``, ``_un`` (engineering units); voltages in V."""

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

from ._results import (
    Calibration,
    Cycle,
    Equilibrium,
    Mode,
    PullIn,
    Sensors,
    StaticHysteresis,
)

__version__: str

F64Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike
Target = Union["Model", "Scene"]

class Scene:
    """A whole head–disk interface, validated. Fields are SI with the unit in their name;
    ``scene["surface.height_sigma_nm"]`` reads and writes a field in an engineering unit."""

    @staticmethod
    def paper() -> Scene:
        """The built-in scene of the letter."""
    @staticmethod
    def from_file(path: Union[str, os.PathLike[str]]) -> Scene:
        """Reads a ``.toml`` or ``.json`` scene file and validates it.

        Raises FileError, SceneError (parse, with the file name) or InvalidInputError."""
    @staticmethod
    def from_toml(text: str) -> Scene:
        """Parses TOML text (engineering units allowed) and validates it."""
    @staticmethod
    def from_json(text: str) -> Scene:
        """Parses JSON text (engineering units allowed) and validates it."""
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> Scene:
        """A scene from a dict shaped as the JSON file (engineering units allowed)."""
    def to_dict(self) -> Dict[str, Any]:
        """The scene as plain Python values, SI units; ``from_dict`` gives it back exactly."""
    def to_toml(self) -> str:
        """The scene as TOML text, SI units."""
    def to_json(self) -> str:
        """The scene as JSON text, SI units."""
    @property
    def name(self) -> str:
        """The scene's name."""
    def __getitem__(self, path: str) -> Any:
        """A field by dotted path, SI (``"surface.height_sigma_m"``) or engineering unit
        (``"surface.height_sigma_nm"``, in nm). KeyError if there is no such field."""
    def __setitem__(self, path: str, value: Any) -> None:
        """Sets a field (SI or engineering unit) and validates the scene again; on
        InvalidInputError the scene is unchanged."""
    def with_values(self, values: Mapping[str, Any]) -> Scene:
        """A validated copy with the fields (dotted paths, SI or engineering units) replaced."""
    def keys(self) -> List[str]:
        """Every field's dotted SI path (``"surface.height_sigma_m"``), in the file's order."""
    def __contains__(self, path: str) -> bool:
        """Whether ``path`` names a field (SI or engineering unit)."""
    def __iter__(self) -> Iterator[str]:
        """The fields' dotted SI paths, as ``keys()``."""
    def __len__(self) -> int: ...
    def __eq__(self, other: object) -> bool: ...

class Model:
    """A scene built into the slider model (force tables, air bearing, heater, voltage).
    Building takes a fraction of a second, without the GIL; share one model across analyses."""

    def __init__(self, scene: Scene) -> None: ...
    def with_relaxing_state(self, tau_s: float, start: Optional[float] = None, *,
                            target_per_nm: float = 0.0,
                            force_un_per_state: float = 0.0) -> "Model":
        """The same model with one more state of its own, relaxing towards ``target_per_nm``
        times the bulge gap (nm) with time constant ``tau_s`` (s) and adding the force
        ``force_un_per_state`` · x (µN); it starts from ``start`` (its equilibrium when None).
        With the defaults, the pure relaxation ``start · exp(−t/τ)``."""
    @property
    def scene(self) -> Scene:
        """A copy of the scene the model was built from."""
    @property
    def structure(self) -> str:
        """The structure's preset as the scene names it: "rigid", "bulge", "pitch", "general"."""
    @property
    def dofs(self) -> int:
        """Degrees of freedom of the structure: the length of ``Equilibrium.q``, ``Mode.shape``."""

class LinearResponse:
    """The linearised slider about its flying equilibrium."""

    @property
    def equilibrium(self) -> Equilibrium:
        """The equilibrium linearised about (under the time-mean V²)."""
    @property
    def modes(self) -> List[Mode]:
        """Every mode by ascending frequency: eigenvalue, frequency, damping ratio, shape. A
        vibrating degree of freedom gives a complex pair; lags and overdamped motions real ones."""
    @property
    def eigenvalues(self) -> List[complex]:
        """Eigenvalues (1/s)."""
    @property
    def frequencies_hz(self) -> List[float]:
        """|Im λ| / 2π (Hz)."""
    @property
    def damping_ratios(self) -> List[float]:
        """−Re λ / |λ|."""
    @property
    def stable(self) -> bool:
        """Whether every eigenvalue has a negative real part."""
    @property
    def gain_at_2f_m_per_n(self) -> float:
        """|H(i·2π·2f)| (m/N)."""
    @property
    def force_at_2f_n(self) -> float:
        """Force amplitude at 2f, |G_e| V_ac²/2 (N)."""
    @property
    def dither_amplitude_m(self) -> float:
        """Predicted dither amplitude at 2f (m)."""
    @property
    def dither_amplitude_nm(self) -> float:
        """Predicted dither amplitude at 2f (nm)."""
    def transfer(self, omega_rad_s: F64Array) -> npt.NDArray[np.complex128]:
        """H(iω) (m/N), displacement per interface force, at each ω (rad/s)."""
    def to_dict(self) -> Dict[str, Any]:
        """The response as plain values: equilibrium, modes, stable, gain_at_2f_m_per_n,
        force_at_2f_n, dither_amplitude_m."""
    def __eq__(self, other: object) -> bool:
        """Equal when every number is, the state-space matrices included. A response pickles
        (every number it holds) and comes back equal."""

SENSOR_COLUMNS: List[str]
"""The columns of a sensor stream (``replay``, ``hdi drive``), units in their names."""

def replay(scene: Union[Scene, Model, Sequence[Scene]], time_s: Sequence[float],
           heater_mw: Sequence[float], voltage_dc_v: Sequence[float],
           voltage_ac_v: Optional[Sequence[float]] = None,
           ac_frequency_khz: Optional[Sequence[float]] = None, *, rate_khz: float = 20.0,
           seed: int = 1, flat_disk: bool = False, atol_pm: Optional[float] = None,
           atol_flight_pm: Optional[float] = None,
           **settings: Any) -> Dict[str, npt.NDArray[Any]]:
    """Replays commands (each holds from its ``time_s`` until the next; the last time ends the
    run) through a new drive, as ``hdi drive SCENE --commands FILE`` does: the sensor columns
    of ``SENSOR_COLUMNS`` as float64 arrays, one value per period, bit for bit the CLI's.
    ``settings`` are the drive settings of ``Drive`` (``radius_mm``, ``rpm``, ``heads``, …);
    with more than one head every head holds the commands, the rows run period by period and
    head by head, and an int64 ``head`` column leads. The GIL is released while the drive
    runs."""

class MultiDrive:
    """The native half of ``hdi_tribology.MultiDrive`` (see there)."""

    def __init__(self, scene: Union[Scene, Model, Sequence[Scene]], *, seed: int = 1,
                 flat_disk: bool = False, atol_pm: Optional[float] = None,
                 atol_flight_pm: Optional[float] = None, **settings: Any) -> None: ...
    def step(self, heater_power_mw: Union[float, Sequence[float]], *,
             dc_voltage_v: Union[float, Sequence[float], None] = None,
             ac_amplitude_v: Union[float, Sequence[float], None] = None,
             ac_frequency_khz: Union[float, Sequence[float], None] = None,
             period_s: float = 50e-6) -> List[Sensors]:
        """Every head's command held for one period; the heads' sensors in head order."""
    @property
    def heads(self) -> int:
        """The number of heads."""
    @property
    def time_s(self) -> float:
        """Simulated time so far (s)."""
    @property
    def seeds(self) -> List[int]:
        """Each head's seed."""

class Forces(TypedDict):
    d_m: F64Array
    intermolecular_n: F64Array
    contact_n: F64Array
    electrostatic_per_volt2_n_per_v2: F64Array
    electrostatic_n: F64Array
    other_n: F64Array
    real_contact_area_m2: F64Array
    total_n: F64Array
    in_table_range: npt.NDArray[np.bool_]

def forces(target: Target, gaps_nm: ArrayLike, protrusion_nm: float = 0.0) -> Forces:
    """Every interface force at bulge gaps ``gaps_nm`` (nm, any array_like of any shape; pad
    gaps ``gaps_nm + protrusion_nm``) at the scene's DC voltage: float64 arrays shaped as
    ``gaps_nm``, in N
    (positive away from the disk), N/V² and m², and ``in_table_range`` (False where a gap lies
    outside the scene's force tables: computed by direct quadrature there)."""

def static_hysteresis(target: Target, contact_threshold_un: Optional[float] = None) -> StaticHysteresis:
    """Static touchdown and take-off at the scene's DC voltage (threshold in µN; default the
    scene detector's)."""

def pull_in_voltage(target: Target, power_mw: float = 0.0, contact_threshold_un: Optional[float] = None) -> PullIn:
    """The voltage |V − φ| (V) that pulls the head in at heater power ``power_mw`` (mW)."""

def clearance_change(target: Target, dc_voltages_v: Sequence[float], contact_threshold_un: Optional[float] = None) -> Dict[str, F64Array]:
    """Clearance change with DC voltage: arrays ``dc_voltage_v`` (V), ``touchdown_power_w``
    (W), ``clearance_change_m`` (m)."""

def s_curve(target: Target) -> Dict[str, Any]:
    """Static equilibria along the gap: arrays ``d_m``, ``y_m``, ``protrusion_m``, ``power_w``,
    ``stiffness_n_per_m``, ``interface_force_n``, ``contact_force_n``, ``stable`` (bool),
    ``volt2_v2``, and ``folds``, a list of ``{"power_w", "d_m", "jump_in"}``."""

def simulate_cycle(
    target: Target,
    v_ac: Optional[float] = None,
    *,
    triggered: bool = False,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    atol_nm: Optional[float] = None,
    series: bool = True,
    stop_at_takeoff: bool = False,
    mean_temperature: bool = True,
) -> Dict[str, Any]:
    """One touchdown/take-off cycle at AC amplitude ``v_ac`` (V; default the scene's), under
    the scene's programme (or the touchdown-triggered protocol). ``rtol`` scales the absolute
    tolerance with it unless ``atol_nm`` (nm) is given, as ``hdi cycle`` does. Returns ``cycle``
    (Cycle, as ``hdi cycle --no-refine`` prints it),
    ``touchdown``/``takeoff`` (Detection or None) and, with ``series``, float64 arrays per
    accepted step: ``t_s``, ``power_w``, ``d_m``, ``air_bearing_n``, ``intermolecular_n``,
    ``electrostatic_n``, ``contact_n``, ``total_n``, ``temperature_rise_k``, ``indicator_n``
    (NaN until the detector window has filled), and ``term_states`` with terms of memory.
    ``stop_at_takeoff`` ends the run at the step where the detector sees take-off: the same
    touchdown and take-off to the bit, the rest over the time run. ``mean_temperature=False``
    leaves the heat integral out of the state: ``mean_temperature_rise_k`` is None, the powers
    move within the tolerance."""

def ac_sweep(
    target: Target,
    amplitudes_v: Optional[Sequence[float]] = None,
    *,
    triggered: bool = False,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    atol_nm: Optional[float] = None,
    threads: Optional[int] = None,
) -> List[Cycle]:
    """One cycle per AC amplitude (V; default the scene's sweep list), on ``threads`` rayon
    threads (default all cores), GIL released, each run once (status ``"unchecked"``); in the
    order of the amplitudes. Ctrl-C stops it."""

def ac_sweep_refined(
    target: Target,
    power_tol_mw: float,
    amplitudes_v: Optional[Sequence[float]] = None,
    *,
    temperature_tol_k: float = 0.05,
    max_runs: int = 4,
    agreeing_runs: int = 2,
    triggered: bool = False,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    atol_nm: Optional[float] = None,
    threads: Optional[int] = None,
) -> List[Cycle]:
    """``ac_sweep`` with the tolerances tightened tenfold per run (at most ``max_runs``) until
    touchdown and take-off move by at most ``power_tol_mw`` (mW) and the mean temperature rise
    by at most ``temperature_tol_k`` (K) over ``agreeing_runs`` successive runs (3 also catches
    a take-off a whole period of V² off in two successive runs alike). Check ``status``."""

def linear_response(target: Target, power_mw: float) -> LinearResponse:
    """The linearised slider about its flying equilibrium at ``power_mw`` (mW): modes,
    transfer function H(iω) and the predicted dither at twice the AC frequency."""

def flying_equilibrium(target: Target, power_mw: float, *,
                       v_ac: Optional[float] = None) -> Equilibrium:
    """The stable flying equilibrium at heater power ``power_mw`` (mW), under the time-mean V²
    of the scene's voltage (AC amplitude ``v_ac`` in V when given): the one ``linear_response``
    linearises about. Raises when the flying branch ends below that power (head in contact)."""

def simulated_dither(target: Target, power_mw: float, v_ac: Optional[float] = None, *,
                     settle: int = 40, periods: int = 10, method: Optional[str] = None,
                     rtol: Optional[float] = None, atol_nm: Optional[float] = None) -> float:
    """Dither amplitude of the bulge at 2f (m) simulated at constant heater power ``power_mw``
    (mW) and AC amplitude ``v_ac`` (V; default the scene's): half the peak-to-peak bulge
    displacement over the last ``periods`` periods of V² after ``settle`` periods. The
    simulated counterpart of ``LinearResponse.dither_amplitude_m``; raises ``AnalysisError``
    without an AC voltage."""

def calibrate(
    target: Target,
    *,
    detector: str = "mean",
    start_mw: Optional[float] = None,
    step_mw: float = 0.5,
    max_mw: Optional[float] = None,
    margin_mw: float = 15.0,
    dither_v: Optional[float] = None,
    find_takeoff: bool = True,
) -> Calibration:
    """Touchdown calibration by heater steps (mW) with detector ``"mean"``, ``"ae"`` or
    ``"vibration"``, optionally under an AC dither (V)."""

def fit(
    scene: Scene,
    data: Sequence[Union[str, os.PathLike[str]]],
    free: Sequence[str],
    *,
    starts: int = 1,
    seed: int = 1,
    max_evaluations: int = 400,
) -> Dict[str, Any]:
    """Fits the ``free`` parameters of ``scene`` (named as a scene file names them, in that
    name's unit, optional bounds: ``"efficiency_nm_per_mw=0.05:0.2"``) to measured curves (CSV
    files in engineering units). Returns ``scene`` (the fitted Scene), ``parameters`` (dicts:
    name, unit, field, value, start, standard_error, linear_error, determined, lower, upper),
    ``correlation``, ``residuals``, ``identifiability``, ``points``, ``chi2``,
    ``residual_scale``, ``converged``, ``termination``, ``evaluations``, ``starts``,
    ``integration``, ``trusted``, ``warnings``. Raises DataFileError on a bad file."""


class AirBearing:
    """The equilibrium of a slider on its air bearing (``bearing``). Attitude in nm and µrad;
    ``stiffness`` and ``damping`` are 3×3 SI matrices, rows (force, pitch moment, roll moment),
    columns (fly height, pitch, roll)."""
    fly_height_nm: float
    pitch_urad: float
    roll_urad: float
    trailing_edge_spacing_nm: float
    bulge_spacing_nm: float
    min_spacing_nm: float
    load_mn: float
    pitch_moment_un_m: float
    roll_moment_un_m: float
    bearing_number: float
    stiffness: List[List[float]]
    damping: List[List[float]]
    imbalance: float
    tolerance: float
    @property
    def converged(self) -> bool: ...
    @property
    def cells(self) -> tuple[int, int]: ...
    @property
    def convergence(self) -> List[Dict[str, Any]]: ...
    @property
    def pressure_pa(self) -> npt.NDArray[np.float64]: ...
    @property
    def x_um(self) -> npt.NDArray[np.float64]: ...
    @property
    def y_um(self) -> npt.NDArray[np.float64]: ...
    def to_dict(self) -> Dict[str, Any]:
        """Every attribute as plain values (``pressure_pa`` as ``ny`` lists of ``nx``); the
        result pickles as this dict and comes back equal."""
    def __eq__(self, other: object) -> bool: ...

def bearing(geometry: Union[str, "os.PathLike[str]"], *, cells: Optional[int] = None,
            radius_mm: Optional[float] = None, rpm: Optional[float] = None,
            skew_deg: Optional[float] = None, preload_mn: Optional[float] = None) -> AirBearing:
    """The attitude of the slider of the bearing file ``geometry`` (TOML, JSON or the text
    format) on ``cells`` control volumes a side (default the file's grid), with the disk radius,
    speed, skew and preload in place of the file's when given: fly height, pitch and roll,
    stiffness, damping, load, pressure and convergence. Raises InvalidInputError naming the
    argument or the file's field, AnalysisError when the slider does not fly."""
