//! Real polynomials in `s`: the numerators and denominators of the balance transfer functions.

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

/// A real polynomial `c₀ sⁿ + c₁ sⁿ⁻¹ + … + cₙ`, coefficients stored highest degree first.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Polynomial {
    /// Coefficients, highest degree first. Never empty.
    pub coefficients: Vec<f64>,
}

impl Polynomial {
    /// The polynomial with the given coefficients (highest degree first); leading zeros are
    /// dropped, an empty list is the zero polynomial `[0]`.
    pub fn new(coefficients: &[f64]) -> Self {
        let first = coefficients.iter().position(|c| *c != 0.0);
        let coefficients = match first {
            Some(i) => coefficients.get(i..).unwrap_or(&[0.0]).to_vec(),
            None => vec![0.0],
        };
        Self { coefficients }
    }

    /// Degree (0 for constants, including the zero polynomial).
    pub fn degree(&self) -> usize {
        self.coefficients.len().saturating_sub(1)
    }

    /// Value at a complex point `s` (Horner's rule).
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        self.coefficients
            .iter()
            .fold(Complex::new(0.0, 0.0), |acc, c| acc * s + *c)
    }

    /// Product of two polynomials.
    pub fn mul(&self, other: &Polynomial) -> Polynomial {
        let mut out = vec![0.0; self.coefficients.len() + other.coefficients.len() - 1];
        for (i, a) in self.coefficients.iter().enumerate() {
            for (j, b) in other.coefficients.iter().enumerate() {
                if let Some(o) = out.get_mut(i + j) {
                    *o += a * b;
                }
            }
        }
        Polynomial::new(&out)
    }

    /// `self + k·other`, aligned at the constant term.
    pub fn add_scaled(&self, k: f64, other: &Polynomial) -> Polynomial {
        let n = self.coefficients.len().max(other.coefficients.len());
        let mut out = vec![0.0; n];
        for (dst, src) in out.iter_mut().rev().zip(self.coefficients.iter().rev()) {
            *dst += src;
        }
        for (dst, src) in out.iter_mut().rev().zip(other.coefficients.iter().rev()) {
            *dst += k * src;
        }
        Polynomial::new(&out)
    }

    /// The monic real polynomial `∏ (s − rᵢ)` of the given roots (complex roots must come in
    /// conjugate pairs for the result to be real; imaginary residue is discarded).
    pub fn from_roots(roots: &[Complex<f64>]) -> Polynomial {
        let mut c = vec![Complex::new(1.0, 0.0)];
        for r in roots {
            let mut next = vec![Complex::new(0.0, 0.0); c.len() + 1];
            for (i, ci) in c.iter().enumerate() {
                if let Some(n) = next.get_mut(i) {
                    *n += ci;
                }
                if let Some(n) = next.get_mut(i + 1) {
                    *n -= ci * r;
                }
            }
            c = next;
        }
        Polynomial::new(&c.iter().map(|z| z.re).collect::<Vec<_>>())
    }

    /// Roots, as the eigenvalues of the companion matrix (any order). Empty for constants.
    pub fn roots(&self) -> Vec<Complex<f64>> {
        let n = self.degree();
        let lead = self.coefficients.first().copied().unwrap_or(0.0);
        if n == 0 || lead == 0.0 {
            return Vec::new();
        }
        let mut m = DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            m[(0, j)] = -self.coefficients.get(j + 1).copied().unwrap_or(0.0) / lead;
        }
        for i in 1..n {
            m[(i, i - 1)] = 1.0;
        }
        m.complex_eigenvalues().iter().copied().collect()
    }
}
