"""Redraws the letter's Fig. 2(b) and Fig. 3(d) with matplotlib from the hdi_tribology package.

    pip install matplotlib          # besides the package itself (see python/README.md)
    python python/examples/paper_figures.py [OUT_DIR]    # default: out/python_figures

Fig. 2(b): the clearance change ΔFH against the DC voltage, from the static model, with a
parabolic fit. Fig. 3(d): the dynamic hysteresis P_TD − P_TO against the AC amplitude, under the
fixed heater programme and the touchdown-triggered protocol. Each amplitude is rerun at tighter
tolerances until touchdown and take-off move by less than 1 % of the static hysteresis; a point
that had not settled is drawn hollow and labelled so, and an amplitude without both detections
(or with a negative difference) is listed, not drawn as if it were a result.
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hdi_tribology as hdi  # noqa: E402


def fig2b(model, out):
    volts = np.round(np.arange(-10, 11) * 0.1, 10)
    cc = hdi.clearance_change(model, volts.tolist())
    dfh_nm = cc["clearance_change_m"] * 1e9
    a, b, c = np.polyfit(volts, dfh_nm, 2)
    print(f"Fig. 2(b): ΔFH = {a:.4f} nm/V² · V² + {b:.2e} nm/V · V + {c:.2e} nm")
    fine = np.linspace(-1, 1, 201)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(volts, dfh_nm, "o", label="static model")
    ax.plot(fine, np.polyval([a, b, c], fine), "-", label=f"fit {a:.3f} nm/V² · V²")
    ax.set_xlabel("DC voltage $V_{dc}$ (V)")
    ax.set_ylabel("clearance change ΔFH (nm)")
    ax.set_title("Fig. 2(b) clearance change against DC voltage")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "fig2b_clearance_vs_dc.png", dpi=120)
    fig.savefig(out / "fig2b_clearance_vs_dc.svg")
    plt.close(fig)


def fig3d(model, scene, out):
    static = hdi.static_hysteresis(model)
    tol_mw = 0.01 * static.hysteresis_mw
    amplitudes = scene["sweep.ac_amplitudes_v"]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    notes = []
    print(f"Fig. 3(d): refined to {tol_mw:.3f} mW; columns V_ac, ΔP (mW), rtol, converged")
    for triggered, colour, label in [(False, "C0", "fixed programme"),
                                     (True, "C1", "touchdown-triggered")]:
        rows = hdi.ac_sweep_refined(model, tol_mw, amplitudes, triggered=triggered)
        good, unsettled, missing = [], [], []
        for r in rows:
            h = r.hysteresis_mw
            print(f"  {label:20s} {r.v_ac_v:5.2f} {h if h is not None else float('nan'):9.4f}"
                  f" {r.rtol:7.0e} {r.converged}")
            if h is None or h < 0:
                missing.append(r.v_ac_v)
            elif r.converged:
                good.append((r.v_ac_v, h))
            else:
                unsettled.append((r.v_ac_v, h))
        # the line breaks (NaN) where an amplitude has no settled, valid value
        settled = dict(good)
        ax.plot([r.v_ac_v for r in rows],
                [settled.get(r.v_ac_v, np.nan) for r in rows], "o-", color=colour,
                label=label)
        if unsettled:
            ax.plot(*zip(*unsettled), "o", mfc="none", color=colour,
                    label=f"{label}: not settled at the last tolerance")
        if missing:
            print(f"  {label}: no valid hysteresis at V_ac = {missing} (not drawn)")
            notes.append(f"{label}: no valid ΔP at " + ", ".join(f"{v:g} V" for v in missing))
    ax.axhline(static.hysteresis_mw, color="grey", ls="--", label="static, $V_{ac}$ = 0")
    if notes:
        ax.text(0.98, 0.97, "\n".join(notes), transform=ax.transAxes, ha="right", va="top",
                fontsize=8)
    ax.set_xlabel("AC amplitude $V_{ac}$ (V)")
    ax.set_ylabel("hysteresis $P_{TD} - P_{TO}$ (mW)")
    f_khz = scene["voltage.ac_frequency_khz"]
    ax.set_title(f"Fig. 3(d) hysteresis against AC amplitude, f = {f_khz:g} kHz")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "fig3d_hysteresis_vs_ac.png", dpi=120)
    fig.savefig(out / "fig3d_hysteresis_vs_ac.svg")
    plt.close(fig)


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_figures")
    out.mkdir(parents=True, exist_ok=True)
    scene = hdi.Scene.paper()
    model = hdi.Model(scene)
    fig2b(model, out)
    fig3d(model, scene, out)
    print(f"figures written to {out}/")


if __name__ == "__main__":
    main()
