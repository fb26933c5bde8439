//! Natural cubic splines: C² interpolation of sampled tracks, so that resampled references
//! have continuous velocity and acceleration.

use crate::error::{check_all_finite, check_dim, Error, Result};

/// A natural cubic spline through samples `(t_i, y_i)`, `i = 0 … n−1`.
///
/// On `[t_i, t_{i+1}]` with `h = t_{i+1} − t_i`, `a = (t_{i+1} − t)/h`, `b = (t − t_i)/h`:
///
/// ```text
/// y(t) = a y_i + b y_{i+1} + ((a³ − a) M_i + (b³ − b) M_{i+1}) h²/6
/// ```
///
/// where the second derivatives `M_i` solve the tridiagonal system
/// `h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i + h_i M_{i+1} = 6((y_{i+1} − y_i)/h_i − (y_i − y_{i−1})/h_{i−1})`
/// with the natural end conditions `M_0 = M_{n−1} = 0` (Press et al., *Numerical Recipes*,
/// §3.3). The spline is twice continuously differentiable: `y`, `ẏ` and `ÿ` are continuous
/// (`ÿ` is piecewise linear). Outside `[t_0, t_{n−1}]` the end values are held (`ẏ = ÿ = 0`);
/// at the end points themselves the end segments' derivatives are returned.
/// With one sample the spline is that constant; with two, the straight line.
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

impl CubicSpline {
    /// The natural cubic spline through `(times[i], values[i])`. Errors: empty or mismatched
    /// input, a non-finite value, times not strictly increasing.
    pub fn new(times: &[f64], values: &[f64]) -> Result<Self> {
        check_dim("spline values", times.len(), values.len())?;
        if times.is_empty() {
            return Err(Error::InsufficientData {
                what: "cubic spline".into(),
                message: "at least one sample is needed".into(),
            });
        }
        check_all_finite("spline times", times)?;
        check_all_finite("spline values", values)?;
        for (i, w) in times.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(Error::InvalidSetting {
                    name: format!("spline time {}", i + 1),
                    value: w[1].to_string(),
                    expected: format!("a time after {} s", w[0]),
                });
            }
        }
        let n = times.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            // Thomas algorithm on the interior unknowns M_1 … M_{n−2}.
            let mut diag = vec![0.0; n];
            let mut rhs = vec![0.0; n];
            for i in 1..n - 1 {
                let h0 = times[i] - times[i - 1];
                let h1 = times[i + 1] - times[i];
                diag[i] = 2.0 * (h0 + h1);
                rhs[i] =
                    6.0 * ((values[i + 1] - values[i]) / h1 - (values[i] - values[i - 1]) / h0);
            }
            for i in 2..n - 1 {
                let sub = times[i] - times[i - 1]; // h_{i−1}, below the diagonal
                let w = sub / diag[i - 1];
                diag[i] -= w * sub;
                rhs[i] -= w * rhs[i - 1];
            }
            for i in (1..n - 1).rev() {
                let sup = times[i + 1] - times[i];
                let next = if i + 1 < n - 1 { m[i + 1] } else { 0.0 };
                m[i] = (rhs[i] - sup * next) / diag[i];
            }
        }
        Ok(Self {
            t: times.to_vec(),
            y: values.to_vec(),
            m,
        })
    }

    /// First and last sample times \[s\].
    pub fn span(&self) -> (f64, f64) {
        (
            self.t.first().copied().unwrap_or(0.0),
            self.t.last().copied().unwrap_or(0.0),
        )
    }

    /// Value, first and second derivative at `t` (units of the values per s⁰, s¹, s²).
    /// Allocates nothing; a non-finite `t` gives NaN.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let n = self.t.len();
        if !t.is_finite() {
            return [f64::NAN; 3];
        }
        let (first, last) = self.span();
        if n == 1 || t < first {
            return [self.y.first().copied().unwrap_or(0.0), 0.0, 0.0];
        }
        if t > last {
            return [self.y.last().copied().unwrap_or(0.0), 0.0, 0.0];
        }
        let i = self.t.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
        self.eval_in(i, t)
    }

    /// Value, first and second derivative at `t` in the interval `[t_i, t_{i+1}]`.
    fn eval_in(&self, i: usize, t: f64) -> [f64; 3] {
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let (y0, y1) = (self.y[i], self.y[i + 1]);
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let h = t1 - t0;
        let a = (t1 - t) / h;
        let b = (t - t0) / h;
        let y = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let yd =
            (y1 - y0) / h - (3.0 * a * a - 1.0) / 6.0 * h * m0 + (3.0 * b * b - 1.0) / 6.0 * h * m1;
        let ydd = a * m0 + b * m1;
        [y, yd, ydd]
    }

    /// The values at the ascending times `times` into `out` (same length), equal to
    /// `eval(t)[0]` at each: the interval is found by walking forward from the last one instead
    /// of a search per time (the plan samples every spline at every tick). Times that do not
    /// ascend are searched as by `eval`. Errors: `out` of another length than `times`.
    pub fn values_at(&self, times: &[f64], out: &mut [f64]) -> Result<()> {
        check_dim("spline output", times.len(), out.len())?;
        let n = self.t.len();
        let (first, last) = self.span();
        let mut i = 0;
        let mut previous = f64::NEG_INFINITY;
        for (o, &t) in out.iter_mut().zip(times) {
            if n == 1 || !t.is_finite() || t < first || t > last || t < previous {
                *o = self.eval(t)[0];
                previous = if t.is_finite() { t } else { f64::NEG_INFINITY };
                continue;
            }
            // The i of `eval`: the last knot at or before t, at most n − 2.
            while i + 2 < n && self.t[i + 1] <= t {
                i += 1;
            }
            while i > 0 && self.t[i] > t {
                i -= 1;
            }
            *o = self.eval_in(i, t)[0];
            previous = t;
        }
        Ok(())
    }
}
