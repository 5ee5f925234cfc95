//! The galvo model options shared by `plan jump` and `plan compare`:
//! the reference galvo of SPEC §6 with per-parameter overrides.

use galvo_planner::model::{Discrete, FlexParams, RigidParams};

/// Model choice on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ModelArg {
    /// θ, ω, I.
    Rigid,
    /// Motor and mirror coupled by a torsional spring (θ, ω, I, φ, ω_φ).
    Flexible,
}

impl ModelArg {
    pub(crate) fn name(self) -> &'static str {
        match self {
            ModelArg::Rigid => "rigid",
            ModelArg::Flexible => "flexible",
        }
    }
}

/// Model and sample-period options shared by `jump` and `compare`.
#[derive(clap::Args, Debug, Clone)]
pub(crate) struct ModelArgs {
    /// Galvo model.
    #[arg(long, value_enum, default_value_t = ModelArg::Rigid)]
    pub(super) model: ModelArg,
    /// Sample period, µs.
    #[arg(long, default_value_t = 10.0, allow_hyphen_values = true)]
    pub(super) ts_us: f64,
    /// Torque constant, N·m/A (default 0.0115).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) kt_nm_per_a: Option<f64>,
    /// Rigid model: rotor + mirror inertia, kg·m² (default 2.0e-8).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) j_kg_m2: Option<f64>,
    /// Coil inductance, H (default 180e-6).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) l_h: Option<f64>,
    /// Coil resistance, Ω (default 2.8).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) r_ohm: Option<f64>,
    /// Drive voltage limit, V (default 24).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) umax_v: Option<f64>,
    /// Flexible model: motor inertia, kg·m² (default 1.0e-8).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) jm_kg_m2: Option<f64>,
    /// Flexible model: mirror inertia, kg·m² (default 1.0e-8).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) jl_kg_m2: Option<f64>,
    /// Flexible model: shaft stiffness, N·m/rad (default: 10 kHz resonance).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "resonance_hz")]
    pub(super) k_nm_per_rad: Option<f64>,
    /// Flexible model: free–free torsional resonance, Hz (sets the stiffness).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) resonance_hz: Option<f64>,
}

/// A discretised model of either kind.
pub(crate) enum Built {
    Rigid(Box<Discrete<3>>),
    Flexible(Box<Discrete<5>>),
}

impl ModelArgs {
    pub(crate) fn ts_s(&self) -> f64 {
        self.ts_us / 1e6
    }

    pub(crate) fn rigid_params(&self) -> RigidParams {
        let r = RigidParams::REFERENCE;
        RigidParams {
            kt_nm_per_a: self.kt_nm_per_a.unwrap_or(r.kt_nm_per_a),
            j_kg_m2: self.j_kg_m2.unwrap_or(r.j_kg_m2),
            l_h: self.l_h.unwrap_or(r.l_h),
            r_ohm: self.r_ohm.unwrap_or(r.r_ohm),
            u_max_v: self.umax_v.unwrap_or(r.u_max_v),
        }
    }

    pub(crate) fn flex_params(&self) -> FlexParams {
        let f = FlexParams::REFERENCE;
        let jm = self.jm_kg_m2.unwrap_or(f.jm_kg_m2);
        let jl = self.jl_kg_m2.unwrap_or(f.jl_kg_m2);
        let k = match (self.k_nm_per_rad, self.resonance_hz) {
            (Some(k), _) => k,
            (None, Some(hz)) => FlexParams::stiffness_for_resonance(jm, jl, hz),
            (None, None) => FlexParams::stiffness_for_resonance(jm, jl, f.resonance_hz()),
        };
        FlexParams {
            kt_nm_per_a: self.kt_nm_per_a.unwrap_or(f.kt_nm_per_a),
            jm_kg_m2: jm,
            jl_kg_m2: jl,
            k_nm_per_rad: k,
            l_h: self.l_h.unwrap_or(f.l_h),
            r_ohm: self.r_ohm.unwrap_or(f.r_ohm),
            u_max_v: self.umax_v.unwrap_or(f.u_max_v),
        }
    }

    /// The rigid galvo with the flexible model's total inertia (the
    /// reference for `compare --model flexible`).
    pub(crate) fn rigid_equivalent(&self) -> RigidParams {
        let f = self.flex_params();
        RigidParams {
            kt_nm_per_a: f.kt_nm_per_a,
            j_kg_m2: f.jm_kg_m2 + f.jl_kg_m2,
            l_h: f.l_h,
            r_ohm: f.r_ohm,
            u_max_v: f.u_max_v,
        }
    }

    /// Validates the options and discretises the chosen model.
    pub(crate) fn build(&self) -> Result<Built, String> {
        match self.model {
            ModelArg::Rigid => {
                let flex_only = [
                    ("--jm-kg-m2", self.jm_kg_m2.is_some()),
                    ("--jl-kg-m2", self.jl_kg_m2.is_some()),
                    ("--k-nm-per-rad", self.k_nm_per_rad.is_some()),
                    ("--resonance-hz", self.resonance_hz.is_some()),
                ];
                if let Some((flag, _)) = flex_only.iter().find(|(_, set)| *set) {
                    return Err(format!("{flag} applies to --model flexible only"));
                }
                let d = self
                    .rigid_params()
                    .model()
                    .and_then(|m| m.discretize(self.ts_s()))
                    .map_err(|e| e.to_string())?;
                Ok(Built::Rigid(Box::new(d)))
            }
            ModelArg::Flexible => {
                if self.j_kg_m2.is_some() {
                    return Err(
                        "--j-kg-m2 applies to --model rigid; use --jm-kg-m2 and --jl-kg-m2".into(),
                    );
                }
                if let Some(hz) = self.resonance_hz
                    && !(hz.is_finite() && hz > 0.0)
                {
                    return Err(format!("resonance_hz must be positive (got {hz})"));
                }
                let d = self
                    .flex_params()
                    .model()
                    .and_then(|m| m.discretize(self.ts_s()))
                    .map_err(|e| e.to_string())?;
                Ok(Built::Flexible(Box::new(d)))
            }
        }
    }
}
