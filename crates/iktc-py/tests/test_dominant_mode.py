"""``iktc.dominant_mode``: the damping ratio and natural frequency of a response's dominant
oscillatory mode (Prony's method, in the Rust library), on known signals and on the damping
controller's own closed loop; no MuJoCo needed."""
import numpy as np
import pytest

import iktc

DT = 0.005  # control period [s]


@pytest.mark.parametrize("zeta,wn", [(0.15, 4.8), (0.55, 4.5), (0.72, 5.0)])
def test_the_damping_ratio_estimate_recovers_a_known_damped_sinusoid(zeta, wn):
    t = np.arange(0.0, 2.0, DT)
    wd = wn * np.sqrt(1 - zeta ** 2)
    y = 0.003 + 0.02 * np.exp(-zeta * wn * t) * np.cos(wd * t + 0.4)
    z, w = iktc.dominant_mode(t, y)
    assert z == pytest.approx(zeta, abs=0.01) and w == pytest.approx(wn, rel=0.01)


def test_the_damping_ratio_estimate_picks_the_dominant_mode_of_several():
    # The shape of a damped closed loop after a push: the designed pair, the observer's pair at
    # twice its frequency, a real lag pole, a lightly damped faster resonance and an offset.
    t = np.arange(0.0, 2.0, DT)

    def mode(zeta, wn, amp, phase):
        return amp * np.exp(-zeta * wn * t) * np.cos(wn * np.sqrt(1 - zeta ** 2) * t + phase)

    y = (0.002 + mode(0.72, 4.9, 0.02, 0.3) + mode(0.72, 9.8, -0.006, 1.0)
         + 0.008 * np.exp(-6.0 * t) + mode(0.15, 30.0, 0.001, 0.0))
    z, w = iktc.dominant_mode(t, y)
    assert z == pytest.approx(0.72, abs=0.01) and w == pytest.approx(4.9, rel=0.01)


def test_the_damping_ratio_estimate_passes_over_a_pair_that_does_not_oscillate_in_the_record():
    # Two nearly equal real decays can come out of Prony's fit as a barely complex pair with a
    # large amplitude (−9.25 ± 0.62j rad/s: a tenth of a cycle in 2 s). It outweighs the
    # designed pair (ζ = 0.7, 5.5 rad/s) in energy but is no oscillation.
    t = np.arange(0.0, 2.0, DT)
    slow = 0.05 * np.exp(-9.25 * t) * np.cos(0.62 * t + 0.2)
    wn, zeta = 5.5, 0.7
    pair = 0.02 * np.exp(-zeta * wn * t) * np.cos(wn * np.sqrt(1 - zeta ** 2) * t + 0.5)
    z, w = iktc.dominant_mode(t, 0.002 + slow + pair)
    assert z == pytest.approx(zeta, abs=0.01) and w == pytest.approx(wn, rel=0.01)


def _expm(m):
    """exp(m) by scaling and squaring of the Taylor series (small, well-scaled matrices)."""
    s = max(0, int(np.ceil(np.log2(max(np.linalg.norm(m, 1), 1e-300)))) + 1)
    a, e, term = m / 2 ** s, np.eye(len(m)), np.eye(len(m))
    for k in range(1, 20):
        term = term @ a / k
        e = e + term
    for _ in range(s):
        e = e @ e
    return e


@pytest.mark.parametrize("design", [0.3, 0.5, 0.72, 0.9])
def test_the_damping_controller_on_its_own_model_measures_its_design_ratio(design):
    # Plant = the model itself (eq. 31 written out here from the corrected eqs. 27–28: IPCJ,
    # lag τ_s driven by its ZMP, Padé (−s + 1/T)/(s + 1/T)), discretised exactly (ZOH) at
    # 5 ms; a push = an initial θ̇. The estimate of the closed loop's dominant pair must be the
    # design: this checks the pole placement and the estimate, with no MuJoCo in between.
    l, km, bm, ts, tp, g = 0.62, 15.5, 0.55, 0.17, 0.002, 9.81
    a = np.zeros((4, 4))
    a[0, 1] = 1.0
    a[1] = [g / l - km / l ** 2, -bm / l ** 2, 0.0, 0.0]
    a[2] = [km / g / ts, bm / g / ts, -1.0 / ts, 0.0]
    a[3, 2:] = [2.0 / tp, -1.0 / tp]
    b = np.array([0.0, km / l ** 2, -km / g / ts, 0.0])
    c = np.array([0.0, 0.0, -1.0, 1.0])
    m = np.zeros((5, 5))
    m[:4, :4], m[:4, 4] = a, b
    e = _expm(m * DT)
    ad, bd = e[:4, :4], e[:4, 4]
    ctrl = iktc.DampingController(iktc.PlaneModel(l, km, bm, ts, tp), damping_ratio=design)
    x = np.array([0.0, 0.05, 0.0, 0.0])
    ys = []
    for _ in range(400):
        y = float(c @ x)
        ys.append(y)
        x = ad @ x + bd * ctrl.step(0.0, y)[0]
    t = np.arange(len(ys)) * DT
    z, w = iktc.dominant_mode(t, np.array(ys))
    wn = np.sqrt(km / l ** 2 - g / l)  # errata eq. 32: the design keeps w_n
    assert z == pytest.approx(design, abs=0.01) and w == pytest.approx(wn, rel=0.01)


def test_bad_input_to_the_estimate_is_an_iktc_error_naming_it():
    t = np.arange(0.0, 2.0, DT)
    y = np.sin(5.0 * t)
    with pytest.raises(iktc.IktcError, match="response samples y"):
        iktc.dominant_mode(t, y[:-1])
    with pytest.raises(iktc.IktcError, match="40 samples"):
        iktc.dominant_mode(t[:40], y[:40])
    bent = t.copy()
    bent[10] += 1e-3
    with pytest.raises(iktc.IktcError, match="response times t"):
        iktc.dominant_mode(bent, y)
    with pytest.raises(iktc.IktcError, match="not finite"):
        iktc.dominant_mode(t, np.where(t > 1.0, np.nan, y))
    with pytest.raises(iktc.IktcError, match="PronySettings::order"):
        iktc.dominant_mode(t, y, order=0)
