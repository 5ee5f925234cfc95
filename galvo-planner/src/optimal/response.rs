//! Closed-form impulse and step responses of the rigid model (complex
//! arithmetic for the two electrical poles).

use crate::linalg::{Matrix, Vector, at, expm_and_integral, mat_vec};
use kinematics_core::numeric::trig;

#[derive(Debug, Clone, Copy, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    const fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, s: f64) -> C {
        C::new(self.re * s, self.im * s)
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn abs(self) -> f64 {
        kinematics_core::numeric::hypot(self.re, self.im)
    }
    /// `e^z − 1`, accurate for small |z|.
    fn exp_m1(self) -> C {
        let s = trig::sin(0.5 * self.im);
        C::new(
            libm::expm1(self.re) * trig::cos(self.im) - 2.0 * s * s,
            libm::exp(self.re) * trig::sin(self.im),
        )
    }
}

/// `E1(z) = (e^z − 1)/z` and `E2(z) = (e^z − 1 − z)/z²`.
fn e12(z: C) -> (C, C) {
    if z.abs() < 0.5 {
        // Series: E1 = Σ z^k/(k+1)!, E2 = Σ z^k/(k+2)!; 20 terms ≪ 1e-17.
        let mut e1 = C::new(0.0, 0.0);
        let mut e2 = C::new(0.0, 0.0);
        let mut zk = C::new(1.0, 0.0);
        let mut fact1 = 1.0; // (k+1)!
        for k in 0..20u32 {
            let f1 = fact1;
            let f2 = fact1 * f64::from(k + 2);
            e1 = e1.add(zk.scale(1.0 / f1));
            e2 = e2.add(zk.scale(1.0 / f2));
            zk = zk.mul(z);
            fact1 = f2;
        }
        (e1, e2)
    } else {
        let em1 = z.exp_m1();
        let e1 = em1.div(z);
        let e2 = em1.sub(z).div(z.mul(z));
        (e1, e2)
    }
}

/// Impulse response `ψ(τ) = e^{Aτ}·B` and step response `Ψ(τ) = ∫₀^τ ψ` of
/// the rigid model. With `c = Kt/J` and the roots p1, p2 of
/// `s² + (R/L)s + Kt²/(J·L)`, writing `Δ[f] = (f(p1) − f(p2))/(p1 − p2)`:
/// `ψ = (c/L)·(Δ[τE1(pτ)], Δ[e^{pτ}], Δ[p·e^{pτ}]/c)`,
/// `Ψ = (c/L)·(Δ[τ²E2(pτ)], Δ[τE1(pτ)], Δ[e^{pτ}]/c)`.
/// Falls back to the matrix exponential when the roots nearly coincide.
#[derive(Debug, Clone, Copy)]
pub(super) struct RigidResponse {
    c: f64,
    inv_l: f64,
    p1: C,
    p2: C,
    a: Matrix<3, 3>,
    b: Vector<3>,
    closed_form: bool,
}

impl RigidResponse {
    pub(super) fn new(kt: f64, j: f64, l: f64, r: f64, a: Matrix<3, 3>, b: Vector<3>) -> Self {
        let alpha = r / l;
        let beta = kt * kt / (j * l);
        let disc = alpha * alpha - 4.0 * beta;
        let (p1, p2) = if disc >= 0.0 {
            // Numerically stable real roots.
            let q = -0.5 * (alpha + libm::sqrt(disc));
            (C::new(q, 0.0), C::new(beta / q, 0.0))
        } else {
            let w = 0.5 * libm::sqrt(-disc);
            (C::new(-0.5 * alpha, w), C::new(-0.5 * alpha, -w))
        };
        let sep = p1.sub(p2).abs();
        let closed_form = sep > 1e-4 * p1.abs().max(p2.abs()) && sep.is_finite();
        Self {
            c: kt / j,
            inv_l: 1.0 / l,
            p1,
            p2,
            a,
            b,
            closed_form,
        }
    }

    /// `(τ·E1(pτ), τ²·E2(pτ), e^{pτ}, p·e^{pτ})` for one root.
    fn root_terms(p: C, tau: f64) -> [C; 4] {
        let z = p.scale(tau);
        let (e1, e2) = e12(z);
        // e^z = 1 + z·E1(z) (exact identity, no second exponential).
        let ez = C::new(1.0, 0.0).add(z.mul(e1));
        [e1.scale(tau), e2.scale(tau * tau), ez, p.mul(ez)]
    }

    /// Real-root version of [`root_terms`](Self::root_terms).
    fn root_terms_real(p: f64, tau: f64) -> [f64; 4] {
        let z = p * tau;
        let (e1, e2) = if libm::fabs(z) < 0.5 {
            // E1 = Σ z^k/(k+1)!, E2 = Σ z^k/(k+2)!; 18 terms ≪ 1e-17.
            let (mut e1, mut e2, mut zk, mut f1) = (0.0, 0.0, 1.0, 1.0);
            for k in 0..18u32 {
                let f2 = f1 * f64::from(k + 2);
                e1 += zk / f1;
                e2 += zk / f2;
                zk *= z;
                f1 = f2;
            }
            (e1, e2)
        } else {
            let em1 = libm::expm1(z);
            (em1 / z, (em1 - z) / (z * z))
        };
        let ez = 1.0 + z * e1;
        [e1 * tau, e2 * tau * tau, ez, p * ez]
    }

    /// `(ψ(τ), Ψ(τ))`.
    pub(super) fn response(&self, tau: f64) -> (Vector<3>, Vector<3>) {
        if !self.closed_form {
            let (e, phi) = expm_and_integral(&self.a, tau);
            return (mat_vec(&e, &self.b), mat_vec(&phi, &self.b));
        }
        // Divided differences Δ[f] = (f(p1) − f(p2))/(p1 − p2).
        let [t1, t2, ex, pex] = if self.p1.im == 0.0 && self.p2.im == 0.0 {
            let a = Self::root_terms_real(self.p1.re, tau);
            let b = Self::root_terms_real(self.p2.re, tau);
            let den = self.p1.re - self.p2.re;
            core::array::from_fn(|i| (at(&a, i) - at(&b, i)) / den)
        } else {
            let a = Self::root_terms(self.p1, tau);
            let b = Self::root_terms(self.p2, tau);
            let den = self.p1.sub(self.p2);
            core::array::from_fn(|i| match (a.get(i), b.get(i)) {
                (Some(x), Some(y)) => x.sub(*y).div(den).re,
                _ => 0.0,
            })
        };
        let k = self.c * self.inv_l;
        (
            [k * t1, k * ex, self.inv_l * pex],
            [k * t2, k * t1, self.inv_l * ex],
        )
    }

    pub(super) fn step_response(&self, tau: f64) -> Vector<3> {
        if tau <= 0.0 {
            [0.0; 3]
        } else {
            self.response(tau).1
        }
    }

    pub(super) fn impulse_response(&self, tau: f64) -> Vector<3> {
        if tau < 0.0 {
            [0.0; 3]
        } else {
            self.response(tau).0
        }
    }
}
