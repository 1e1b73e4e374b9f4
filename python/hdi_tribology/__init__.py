"""hdi_tribology: tribology of the head-disk interface of hard disk drives.

Python bindings of the Rust crate ``hdi-tribology``: the same code, the same numbers. Inputs
are in engineering units where their name says so (``power_mw``, ``gaps_nm``, ``v_ac`` in V);
results carry their SI unit in their name (``power_w``, ``d_m``, ``total_n``), with the same
value in mW, nm or µN beside them (``power_mw``, ``d_nm``, ``total_un``). Each result is the
crate's one representation of it, the JSON the ``hdi`` program prints: ``to_dict()`` gives it
back, results compare by value and pickle, and ``to_dataframe`` makes a pandas table of those
whose shape is one (pandas optional).

>>> import hdi_tribology as hdi
>>> model = hdi.Model(hdi.Scene.paper())
>>> h = hdi.static_hysteresis(model)
>>> round(h.touchdown.power_mw, 1) > round(h.takeoff.power_mw, 1)
True
"""

from ._core import (
    AirBearing,
    LinearResponse,
    Model,
    SENSOR_COLUMNS,
    Scene,
    __version__,
    ac_sweep,
    ac_sweep_refined,
    bearing,
    calibrate,
    clearance_change,
    fit,
    flying_equilibrium,
    forces,
    linear_response,
    pull_in_voltage,
    replay,
    s_curve,
    simulate_cycle,
    simulated_dither,
    static_hysteresis,
)
from ._drive import Drive, MultiDrive
from ._tables import to_dataframe
from ._results import (
    Calibration,
    Cycle,
    Detection,
    Equilibrium,
    Mode,
    PullIn,
    Result,
    Sensors,
    StaticHysteresis,
    Transition,
)
from ._errors import (
    AnalysisError,
    DataFileError,
    FileError,
    HdiError,
    InvalidInputError,
    NoConvergenceError,
    SceneError,
    SolverError,
)

__all__ = [
    "AirBearing",
    "AnalysisError",
    "Calibration",
    "Cycle",
    "DataFileError",
    "Detection",
    "Drive",
    "Equilibrium",
    "FileError",
    "HdiError",
    "InvalidInputError",
    "LinearResponse",
    "Mode",
    "Model",
    "MultiDrive",
    "NoConvergenceError",
    "PullIn",
    "Result",
    "SENSOR_COLUMNS",
    "Scene",
    "SceneError",
    "Sensors",
    "SolverError",
    "StaticHysteresis",
    "Transition",
    "__version__",
    "ac_sweep",
    "ac_sweep_refined",
    "bearing",
    "calibrate",
    "clearance_change",
    "fit",
    "flying_equilibrium",
    "forces",
    "linear_response",
    "pull_in_voltage",
    "replay",
    "s_curve",
    "simulate_cycle",
    "simulated_dither",
    "static_hysteresis",
    "to_dataframe",
]
