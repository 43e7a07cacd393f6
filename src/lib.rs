//! # vrw: passive dynamic walking of a viscoelastic-legged rimless wheel
//!
//! vrw simulates the viscoelastic-legged rimless wheel (VRW) of "Indicators for Emergence of Double-limb
//! Support in Passive Dynamic Walking", decides at every touchdown whether double-limb support (DLS) emerges
//! with the paper's DLS indicators (`lambda_I4`, `lambda_2+`, `lambda_4+`), finds the walking gait and its
//! stability, sweeps parameters and draws the paper's Fig. 2.
//!
//! The model is written down in `docs/model.md` of the repository: coordinates, bodies, contacts, events,
//! the impact procedure, the step map, the audits, the numerical settings and every choice vrw makes where
//! the paper is silent. Every module cites the section of that file (a few comments still call it
//! `MODEL.md`; the section numbers are the same) and the paper's equation it implements.
//!
//! The modules follow the pipeline:
//!
//! | stage | module |
//! |---|---|
//! | parameters and options | [`params`] |
//! | equations of motion, Eq. (1) | [`dynamics`] |
//! | contacts, stoppers, KKT and impulse solves, Eqs. (2), (5) | [`contact`] |
//! | integration with event location | [`integrate`] |
//! | the hybrid walk: phases, events, the DLS-indicator impact procedure | [`walk`], [`walk::impact`] |
//! | step map, gait, Floquet multipliers, sweeps, thresholds | [`gait`] |
//! | tables and figures | [`output`] |
//! | the command-line jobs | [`app`] |
//!
//! ## From parameters to a gait
//!
//! ```
//! use vrw::dynamics::Model;
//! use vrw::gait::{find_gait, GaitOptions, StepMap};
//! use vrw::params::Config;
//! use vrw::walk::{simulate, SectionState};
//!
//! // The paper's Table 1, with c = 50 N s/m.
//! let mut config = Config::default();
//! config.apply_override("viscosity=50").unwrap();
//! config.validate().unwrap();
//! let model = Model::new(&config.params).unwrap();
//!
//! // Walk five steps from a point of the Poincare section (L2, dtheta/dt, dL2/dt).
//! let start = SectionState { l2: 0.72, theta_dot: 1.0, l2_dot: 0.0 };
//! let run = simulate(&model, &config.solver, &start, 5, None).unwrap();
//! assert!(run.failure.is_none());
//! let first = &run.steps[0];
//! assert!(first.indicators.lambda_i4 > 0.0); // the DLS collision pushes the rear leg
//! assert!(first.energy.residual.abs() < 1e-8); // energy audit closes
//!
//! // The gait: a fixed point of the step map, and its Floquet multipliers.
//! let map = StepMap::new(&model, &config.solver);
//! let gait = find_gait(&map, &start, &GaitOptions::default(), None).unwrap();
//! assert!(gait.residual < 1e-10 && gait.stable);
//! println!("lambda_4+ = {} N, multipliers {:?}", gait.lambda_4_plus, gait.floquet_multipliers);
//! ```
//!
//! [`walk::simulate`] keeps every step report in memory. For long walks, [`walk::simulate_streaming`] hands
//! each report to a callback as soon as its step is done and stops when an interrupt flag is set, and
//! [`walk::Trajectory::streaming`] hands each sample to a [`walk::SampleSink`] (such as
//! [`output::TrajectoryCsv`]). This is how `vrw simulate` runs in bounded memory ([`app::run_simulate`]).
#![warn(missing_docs, unnameable_types)]

pub mod app;
pub mod contact;
pub mod dynamics;
pub(crate) mod fmt;
pub mod gait;
pub mod integrate;
pub mod output;
pub mod params;
pub mod reference;
pub mod walk;
