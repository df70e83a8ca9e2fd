"""Plots of the servo-loop analysis: Bode, Nyquist, root loci, pole map (report units on the axes: Hz, N/um).

Each function draws from computed data (:mod:`drakecreep.servo.loops`, :mod:`drakecreep.servo.polemap`) and writes
one PNG; none of them computes a model.
"""

import math

import control  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drakecreep.servo.loops import LOOPS  # noqa: E402

__all__ = [
    "plot_bode",
    "plot_nyquist",
    "plot_gain_locus",
    "plot_parameter_loci",
    "plot_pole_map",
    "plot_step_and_feed",
]

_STYLE = {"continuous": dict(ls="--", lw=1.0), "sampled": dict(ls="-", lw=1.3)}
_COLOR = {"velocity": "C0", "position": "C3"}


def _grid(L, lo=0.1):
    top = 0.5 / L.dt if L.isdtime(strict=True) else 5e3
    return np.logspace(math.log10(lo), math.log10(top * 0.999), 2000)


def _resp(L, f):
    return np.asarray(control.frequency_response(L, 2 * np.pi * f).complex).reshape(-1)


def plot_bode(analysis, path):
    """Bode plot of both loop gains, continuous (dashed) and sampled (solid), crossovers marked."""
    fig, (axm, axp) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, constrained_layout=True)
    for variant, loops in analysis.loops.items():
        for loop in LOOPS:
            L = loops[loop]
            f = _grid(L)
            r = _resp(L, f)
            label = f"{loop} loop, {variant}"
            axm.semilogx(f, 20 * np.log10(np.abs(r)), color=_COLOR[loop], label=label, **_STYLE[variant])
            axp.semilogx(f, np.degrees(np.unwrap(np.angle(r))), color=_COLOR[loop], **_STYLE[variant])
            m = analysis.margins[variant][loop]
            if variant == ("sampled" if analysis.sampled else "continuous") and math.isfinite(m["crossover_Hz"]):
                axm.axvline(m["crossover_Hz"], color=_COLOR[loop], lw=0.6, alpha=0.5)
                axp.axvline(m["crossover_Hz"], color=_COLOR[loop], lw=0.6, alpha=0.5)
    axm.axhline(0, color="k", lw=0.6)
    for k in (-180, -540):
        axp.axhline(k, color="k", lw=0.6)
    if math.isfinite(analysis.resonance_Hz):
        for ax in (axm, axp):
            ax.axvline(analysis.resonance_Hz, color="C2", ls=":", lw=1)
        axm.text(analysis.resonance_Hz, axm.get_ylim()[1], " screw resonance", color="C2", va="top", fontsize=8)
    axm.set_ylabel("|L| (dB)")
    axp.set_ylabel("phase of L (deg)")
    axp.set_xlabel("frequency (Hz)")
    axm.legend(fontsize=8, loc="lower left")
    axm.set_title("loop gains broken at the speed feedback (velocity) and the position feedback (position)",
                  fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_nyquist(analysis, path):
    """Nyquist curves of both loops near -1, with the ``Ms`` circle of each loop."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    main = "sampled" if analysis.sampled else "continuous"
    for ax, loop in zip(axes, LOOPS):
        for variant, loops in analysis.loops.items():
            L = loops[loop]
            f = _grid(L, lo=0.01)
            r = _resp(L, f)
            ax.plot(r.real, r.imag, color=_COLOR[loop], label=f"{variant}, f > 0", **_STYLE[variant])
            ax.plot(r.real, -r.imag, color=_COLOR[loop], alpha=0.35, **_STYLE[variant])
        ms = analysis.margins[main][loop]["ms_peak"]
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(-1 + np.cos(t) / ms, np.sin(t) / ms, color="0.5", lw=0.8, label=f"1/Ms circle (Ms = {ms:.2f})")
        ax.plot(np.cos(t), np.sin(t), color="0.8", lw=0.6)
        ax.plot([-1], [0], "k+", ms=12, mew=2)
        ax.set_xlim(-3, 1.5)
        ax.set_ylim(-2.5, 2.5)
        ax.set_aspect("equal")
        ax.axhline(0, color="k", lw=0.4)
        ax.axvline(0, color="k", lw=0.4)
        ax.set_title(f"{loop} loop (zoom on -1)", fontsize=9)
        ax.set_xlabel("Re L")
        ax.set_ylabel("Im L")
        ax.legend(fontsize=8, loc="lower right")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_gain_locus(analysis, path, factors=None):
    """Root locus of the velocity loop versus a factor on its PI gains (continuous s-plane, sampled z-plane)."""
    factors = np.geomspace(0.05, 20, 240) if factors is None else np.asarray(factors)
    variants = list(analysis.loops)
    fig, axes = plt.subplots(1, len(variants), figsize=(6 * len(variants), 5.2), constrained_layout=True,
                             squeeze=False)
    for ax, variant in zip(axes[0], variants):
        L = analysis.loops[variant]["velocity"]
        pts = np.array([control.feedback(k * L, 1).poles() for k in factors])
        discrete = L.isdtime(strict=True)
        kk = np.repeat(factors, pts.shape[1])
        sc = ax.scatter(pts.real.ravel(), pts.imag.ravel(), c=np.log10(kk), s=4, cmap="viridis")
        nominal = control.feedback(L, 1).poles()
        ax.plot(nominal.real, nominal.imag, "r^", ms=7, mfc="none", label="nominal gains")
        ol = L.poles()
        ax.plot(ol.real, ol.imag, "kx", label="open-loop poles")
        z = L.zeros()
        ax.plot(z.real, z.imag, "ko", mfc="none", label="zeros")
        if discrete:
            t = np.linspace(0, 2 * np.pi, 300)
            ax.plot(np.cos(t), np.sin(t), color="0.5", lw=0.8)
            ax.set_xlim(-1.2, 1.2)
            ax.set_ylim(-1.2, 1.2)
            ax.set_aspect("equal")
            ax.set_xlabel("Re z")
            ax.set_ylabel("Im z")
        else:
            ax.axvline(0, color="k", lw=0.6)
            ax.set_xlim(-1200, 200)
            ax.set_ylim(-800, 800)
            ax.set_xlabel("Re s (1/s)")
            ax.set_ylabel("Im s (rad/s)")
        fig.colorbar(sc, ax=ax, label="log10(gain factor on kv, ki)")
        ax.set_title(f"velocity loop, {variant} ({'z-plane' if discrete else 's-plane'})", fontsize=9)
        ax.legend(fontsize=7, loc="lower left")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_parameter_loci(loci, path, labels=None, crossings=None):
    """Closed-loop poles versus physical parameters, one panel per locus from :func:`polemap.parameter_locus`.

    ``labels``: axis text per locus name; ``crossings``: text added to the friction-slope panel.
    """
    fig, axes = plt.subplots(1, len(loci), figsize=(5.4 * len(loci), 5), constrained_layout=True, squeeze=False)
    for ax, locus in zip(axes[0], loci):
        vals = locus["values"]
        color_val = np.log10(vals * (1e3 if locus["name"] == "feed" else 1.0))
        for v, poles in zip(color_val, locus["poles"]):
            sc = ax.scatter(poles.real, poles.imag, c=np.full(len(poles), v), s=6, cmap="plasma",
                            vmin=color_val.min(), vmax=color_val.max())
        ax.axvline(0, color="k", lw=0.6)
        ax.set_xlim(-600, 400)
        ax.set_ylim(-700, 700)
        ax.set_xlabel("Re s (1/s)")
        ax.set_ylabel("Im s (rad/s)")
        name = (labels or {}).get(locus["name"], locus["name"])
        fig.colorbar(sc, ax=ax, label=f"log10({name})")
        title = f"closed-loop poles vs {name}"
        if locus["name"] == "feed" and crossings:
            title += "\n" + crossings
        ax.set_title(title, fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_pole_map(pm, path):
    """Stiffness x (C + C1) plane: rightmost closed-loop pole, the linear boundaries, the paper's condition."""
    fig, ax = plt.subplots(figsize=(9, 8), constrained_layout=True)
    Kum = pm.stiffness * 1e-6
    X = np.broadcast_to(Kum, pm.damping.shape)
    lim = np.max(np.abs(pm.closed_loop))
    cf = ax.contourf(X, pm.damping, pm.closed_loop, levels=np.linspace(-lim, lim, 41), cmap="RdBu_r")
    fig.colorbar(cf, ax=ax, label="real part of the rightmost closed-loop pole (1/s); red = unstable")
    cs1 = ax.contour(X, pm.damping, pm.closed_loop, levels=[0.0], colors="k", linewidths=2)
    cs2 = ax.contour(X, pm.damping, pm.mechanism, levels=[0.0], colors="C2", linewidths=1.5, linestyles="--")
    ax.axhline(0.0, color="C1", lw=1.5, ls=":")
    kk = np.geomspace(pm.stiffness.min(), pm.stiffness.max(), 200)
    ax.plot(kk * 1e-6, pm.paper_boundary(kk), color="m", lw=2)
    handles = [
        plt.Line2D([], [], color="k", lw=2, label="linear stability boundary, whole servo loop (Drake linearization)"),
        plt.Line2D([], [], color="C2", lw=1.5, ls="--", label="linear boundary, paper mechanism (motor motion prescribed)"),
        plt.Line2D([], [], color="C1", lw=1.5, ls=":", label="C + C1 = 0 (paper eq. 2)"),
        plt.Line2D([], [], color="m", lw=2, label="paper creep condition D^2 = 4 pi zeta (above: no creep)"),
    ]
    if len(pm.sim_creep):
        c = pm.sim_creep
        ax.scatter(pm.sim_stiffness[c] * 1e-6, pm.sim_damping[c], marker="x", color="k", s=40, zorder=5)
        ax.scatter(pm.sim_stiffness[~c] * 1e-6, pm.sim_damping[~c], marker="o", facecolor="none", edgecolor="k",
                   s=40, zorder=5)
        handles += [
            plt.Line2D([], [], marker="x", color="k", ls="", label="simulated: creep (table sticks)"),
            plt.Line2D([], [], marker="o", mfc="none", color="k", ls="", label="simulated: steady sliding"),
        ]
    ax.plot([pm.nominal[0] * 1e-6], [pm.nominal[1]], "y*", ms=16, mec="k", zorder=6)
    handles.append(plt.Line2D([], [], marker="*", color="y", mec="k", ms=12, ls="", label="parameters used"))
    ax.set_xscale("log")
    span = pm.damping.max() - pm.damping.min()
    ax.set_ylim(pm.damping.min() - 0.02 * span, pm.damping.max())
    ax.set_xlabel("axial stiffness K of the screw chain (N/um)")
    ax.set_ylabel("effective damping C + C1 (N s/m)")
    ax.set_title(f"pole map at feed {pm.feed * 1e3:g} mm/s, M = {pm.mass:.4g} kg, Fs - Fc = {pm.friction_drop:.3g} N",
                 fontsize=9)
    ax.legend(handles=handles, fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2)
    del cs1, cs2
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_step_and_feed(step, feed, path):
    """Two simulations: a speed step (table and motor speed vs reference) and a low-speed feed."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), constrained_layout=True)
    for ax, r, title in ((axes[0], step, "speed step"), (axes[1], feed, "low-speed feed")):
        t, s = r.time, r.signals
        ax.plot(t, s["v_ref"] * 1e3, "k--", lw=0.8, label="reference")
        ax.plot(t, s["motor_velocity"] * 1e3, color="0.6", lw=0.8, label="motor (at the table)")
        ax.plot(t, s["table_speed"] * 1e3, color="C0", lw=1.0, label="table")
        ax.set_ylabel("speed (mm/s)")
        ax.set_xlabel("time (s)")
        m = r.metrics
        extra = ""
        if m is not None:
            extra = (f": max fluctuation {m.max_fluctuation * 1e3:.3g} mm/s, stick {m.stick_fraction * 100:.1f} %, "
                     f"{m.stick_slip_cycles} stick-slip cycles")
        ax.set_title(f"{title}, {r.scenario.feed * 1e3:g} mm/s, load case {r.scenario.load_case}{extra}", fontsize=9)
        ax.legend(fontsize=8, loc="lower right")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
