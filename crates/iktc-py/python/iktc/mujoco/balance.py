"""Identification of the IPCJ model on the MuJoCo G1 (Section 4.2) and the push test of the
damping controller (Section 4.3). The damping ratio of a response is ``iktc.dominant_mode``."""
from __future__ import annotations

import math
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

import iktc

from .loop import Log, Loop
from .plant import CONTROL_PERIOD, FloatArray

#: Sine-sweep command amplitude A [rad] (COM offset l·A): larger beats rounding, smaller stays
#: linear (MuJoCo here is noise-free).
SWEEP_AMPLITUDE = 0.005
#: Sweep band [Hz]: the IPCJ mode (≈ 0.8 Hz on this plant) and an octave above; beyond ≈ 1.5 Hz
#: the plant's phase turns back up towards a second resonance near 6 Hz that eq. (31) has no
#: term for, and a fit over 0.25–2 Hz is 4× worse (17 % rms relative error against 4 %).
SWEEP_BAND = (0.25, 1.4)


def _axis(axis: int) -> int:
    if axis not in (0, 1):
        raise iktc.IktcError(f"axis = {axis!r}: expected 0 (x, sagittal) or 1 (y, lateral)")
    return axis


def standing_loop(settle: float = 4.0, **kw: Any) -> Loop:
    """A loop whose imitation holds the start of the clip (its first 1/60 s, then still), with
    the COM reference settled over the centre of the support polygon; `kw`: keywords of
    ``Loop``."""
    loop = Loop(duration=CONTROL_PERIOD, **kw)
    for _ in range(int(round(settle / CONTROL_PERIOD))):
        loop.step(com_offset=(0.0, 0.0))
    loop.feet0 = [loop.plant.foot_pose(i) for i in range(2)]
    loop.log = Log()
    return loop


def pendulum_length(loop: Loop) -> float:
    """l [m]: the COM's height above the ground (the soles), iktc's kinematic COM."""
    return float(loop.sim.com()[2])


def sine_response(loop: Loop, axis: int, freq: float, settle: float, cycles: int,
                  min_time: float, amplitude: float = SWEEP_AMPLITUDE) -> complex:
    """y_ZMP/u at `freq` [Hz] on the plant, the procedure of Section 4.2 as in iktc's
    ``balance::sweep``: u_k = A sin(ω k Δt) sent each tick as the COM offset l·u_k along
    `axis` (0: x, 1: y), its amplitude raised from 0 over the first half of `settle` [s] by a
    half cosine (less transient of the lightly damped mode to wait for); after `settle`, the ZMP
    sampled at the start of each tick is
    fitted by least squares with a sin ωt + b cos ωt + c over a whole number of periods; the
    response is (a + j b) / (A · H_zoh(jω)), H_zoh(jω) = (1 − e^{−jωΔt})/(jωΔt)."""
    _axis(axis)
    if not (math.isfinite(freq) and freq > 0.0):
        raise iktc.IktcError(f"freq = {freq}: expected a frequency > 0 [Hz]")
    dt = CONTROL_PERIOD
    w = 2 * math.pi * freq
    length = pendulum_length(loop)
    period = 1.0 / freq
    n_cycles = max(cycles, math.ceil(min_time / period))
    n_settle = int(round(settle / dt))
    n_meas = int(round(n_cycles * period / dt))
    if n_meas < 3:
        raise iktc.IktcError(f"cycles = {cycles}, min_time = {min_time}: fewer than 3 samples "
                             "to fit")
    rows, ys = [], []
    for k in range(n_settle + n_meas):
        t = k * dt
        if k >= n_settle:
            zmp, _ = loop.plant.zmp()
            if zmp is None:
                raise iktc.IktcError(f"no ZMP at {t:.3f} s of the sweep at {freq} Hz: the feet "
                                     "left the ground")
            rows.append([math.sin(w * t), math.cos(w * t), 1.0])
            ys.append(zmp[axis])
        ramp = 1.0 if t >= settle / 2 else 0.5 - 0.5 * math.cos(2 * math.pi * t / settle)
        u = ramp * amplitude * math.sin(w * t)
        off = [0.0, 0.0]
        off[axis] = length * u
        loop.step(com_offset=(off[0], off[1]))
    a, b, _ = np.linalg.lstsq(np.array(rows), np.array(ys), rcond=None)[0]
    s = 1j * w * dt
    zoh = (1 - np.exp(-s)) / s
    return complex(a + 1j * b) / (amplitude * zoh)


def frequency_response(loop: Loop, axis: int = 0, freqs: Optional[Sequence[float]] = None,
                       settle: float = 3.0, cycles: int = 5, min_time: float = 2.0
                       ) -> Tuple[FloatArray, FloatArray, FloatArray]:
    """(ω [rad/s], magnitude [m/rad], phase [rad]) measured on the plant, 10 frequencies
    log-spaced over SWEEP_BAND by default."""
    f = np.geomspace(*SWEEP_BAND, 10) if freqs is None else np.asarray(freqs, dtype=float)
    resp = [sine_response(loop, axis, float(x), settle, cycles, min_time) for x in f]
    omega = 2 * math.pi * f
    return omega, np.abs(resp), np.unwrap(np.angle(resp))


def identify_on_plant(axis: int = 0, **kw: Any
                      ) -> Tuple[iktc.PlaneModel, Dict[str, float],
                                 Tuple[FloatArray, FloatArray, FloatArray]]:
    """(model, fit, data): eq. (31) fitted (``iktc.identify``) to the plant's frequency response
    (`kw`: keywords of ``frequency_response``); `fit` adds the model's own prediction error at
    the measured points (rms of |H_model − H|/|H| and the largest phase error [deg])."""
    loop = standing_loop()
    omega, mag, phase = frequency_response(loop, axis, **kw)
    model, fit = iktc.identify(list(omega), list(mag), list(phase))
    pred = np.array([model.frequency_response(w) for w in omega])
    h = mag * np.exp(1j * phase)
    hm = pred[:, 0] * np.exp(1j * pred[:, 1])
    fit = dict(fit)
    fit["prediction_rms_relative_error"] = float(np.sqrt(np.mean(np.abs(hm - h) ** 2 / np.abs(h) ** 2)))
    dphi = np.angle(hm / h)
    fit["prediction_max_phase_error_deg"] = float(np.degrees(np.abs(dphi).max()))
    return model, fit, (omega, mag, phase)


def push_test(model: Optional[iktc.PlaneModel] = None, damping: float = 0.72,
              push_force: float = 60.0, push_time: float = 0.05, axis: int = 0,
              after: float = 2.0) -> Tuple[Loop, FloatArray, FloatArray]:
    """A push in double support: `push_force` [N] along `axis` at the pelvis for `push_time`
    [s], then `after` [s] observed. With `model` (an identified PlaneModel) the damping
    controller (Section 4.3, pole damping ratio `damping`, natural frequency kept) feeds the
    measured ZMP back into a COM offset; without, the COM reference stays. The controller's
    command u [rad] becomes the COM offset l·u with the l of the identification's sweep
    (``pendulum_length``, the kinematic COM height), not the fitted pendulum length the
    controller's own `com_offset` uses: the plant the model was fitted to took its input
    through that l. Returns (loop, t [s], ZMP deviation [m] after the push); its damping
    ratio is ``iktc.dominant_mode(t, y)``."""
    _axis(axis)
    for name, value in (("push_time [s]", push_time), ("after [s]", after)):
        if not (math.isfinite(value) and value >= 0.0):
            raise iktc.IktcError(f"{name} = {value}: expected a time >= 0")
    loop = standing_loop()
    length = pendulum_length(loop)
    ctrl = None if model is None else iktc.DampingController(model, damping_ratio=damping,
                                                             control_period=CONTROL_PERIOD)
    zmp0, _ = loop.plant.zmp()
    if zmp0 is None:
        raise iktc.IktcError("no ZMP before the push: the standing robot's feet are unloaded")
    y0 = zmp0[axis]
    n_push = int(round(push_time / CONTROL_PERIOD))
    ts, ys = [], []
    for k in range(n_push + int(round(after / CONTROL_PERIOD))):
        zmp, _ = loop.plant.zmp()
        y = (zmp[axis] - y0) if zmp is not None else 0.0
        off = [0.0, 0.0]
        if ctrl is not None:
            off[axis] = length * ctrl.step(0.0, y)[0]
        force = None
        if k < n_push:
            force = np.zeros(3)
            force[axis] = push_force
        loop.step(com_offset=(off[0], off[1]), push=force)
        if k >= n_push:
            ts.append((k - n_push) * CONTROL_PERIOD)
            ys.append(y)
    return loop, np.array(ts), np.array(ys)
