"""Results as pandas tables: ``to_dataframe``. pandas is optional: it is imported only when a
table is asked for."""

from typing import Any, Dict, List, Mapping, Sequence

import numpy as np

from ._results import Result


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:
        raise ImportError(
            "hdi_tribology.to_dataframe needs the package pandas, which is not installed "
            "(pip install pandas)"
        ) from e
    return pandas


def _flat(d: Mapping[str, Any], tables: Sequence[str], prefix: str = "") -> Dict[str, Any]:
    """``d`` with the mappings named in ``tables`` spread into columns ``key_subkey``."""
    out: Dict[str, Any] = {}
    for k, v in d.items():
        name = prefix + k
        if name in tables:
            if v is not None:
                out.update(_flat(v, tables, name + "_"))
        else:
            out[name] = v
    return out


def _nested(rows: List[Mapping[str, Any]], prefix: str = "") -> List[str]:
    """The keys (``key``, ``key_subkey``, …) whose values are mappings in some row."""
    found: List[str] = []
    for row in rows:
        for k, v in row.items():
            name = prefix + k
            if isinstance(v, Mapping) and name not in found:
                found.append(name)
                found += [n for n in _nested([v], name + "_") if n not in found]
    return found


def _records(items: Sequence[Any]) -> Any:
    rows = [r.to_dict() if isinstance(r, Result) else dict(r) for r in items]
    tables = _nested(rows)
    flat = [_flat(r, tables) for r in rows]
    columns: List[str] = []
    for r in flat:
        columns += [k for k in r if k not in columns]
    return _pandas().DataFrame(flat, columns=columns)


def _columns(d: Mapping[str, Any]) -> Any:
    arrays = [v for v in d.values() if isinstance(v, np.ndarray)]
    if not arrays:
        raise TypeError("to_dataframe: the dict holds no arrays to make columns of")
    # The rows: the first 0-d or 1-d array's, else (``forces`` of an N-d array) the first's.
    shape = next((v for v in arrays if v.ndim <= 1), arrays[0]).shape
    n = int(np.prod(shape))
    columns: Dict[str, Any] = {}
    rest: Dict[str, Any] = {}
    for k, v in d.items():
        if isinstance(v, np.ndarray) and v.shape == shape:
            columns[k] = v.reshape(n)
        elif isinstance(v, np.ndarray) and v.ndim == 2 and len(shape) == 1 and v.shape[1] == n:
            # one row per state over the steps (``term_states``): a column per state
            for i, row in enumerate(v):
                columns[f"{k}_{i}"] = row
        else:
            rest[k] = v
    frame = _pandas().DataFrame(columns)
    # What is not a column (the cycle of ``simulate_cycle``, the folds of ``s_curve``) rides
    # along in ``attrs``.
    frame.attrs.update(rest)
    return frame


def to_dataframe(result: Any) -> Any:
    """A ``pandas.DataFrame`` of a result whose natural shape is a table, with the result's own
    column names (the unit in each: ``power_w``, ``d_m``, ``v_ac_v``):

    - a dict of arrays (``replay``, ``simulate_cycle``'s series, ``forces``, ``s_curve``,
      ``clearance_change``): one column per array of the common shape (flattened), one row per
      value; ``term_states`` gives a column per state (``term_states_0``, …). Everything else in
      the dict (``cycle``, ``touchdown``, ``folds``) is kept in ``frame.attrs``.
    - a list of results or dicts (``ac_sweep``, ``ac_sweep_refined``, ``Calibration.steps``, the
      ``Sensors`` of a firmware loop): one row each, nested records spread into columns
      (``touchdown_power_w``, ``stats_accepted``, ``truth_gap_nm``); a missing record (a
      touchdown not detected) leaves its columns empty (NaN).
    - one result: a table of one row.

    A value that does not exist is missing (NaN or None), as in the CSV files (an empty field).
    pandas is imported here, not with ``hdi_tribology``: without it this raises ``ImportError``.
    """
    if isinstance(result, Result):
        return _records([result])
    if isinstance(result, Mapping):
        return _columns(result)
    if isinstance(result, (list, tuple)):
        return _records(result)
    raise TypeError(
        f"to_dataframe takes a dict of arrays, a list of results or a result, "
        f"not {type(result).__name__}"
    )
