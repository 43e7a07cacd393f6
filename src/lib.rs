//! # vrw: passive dynamic walking of a viscoelastic-legged rimless wheel
//!
//! vrw simulates the viscoelastic-legged rimless wheel (VRW) of "Indicators for Emergence of Double-limb
//! Support in Passive Dynamic Walking", decides at every touchdown whether double-limb support (DLS) emerges
//! with the paper's DLS indicators (`lambda_I4`, `lambda_2+`, `lambda_4+`), finds the walking gait and its
//! stability, sweeps parameters and draws the paper's Fig. 2.
//!
//! The model is written down in `docs/model.md` of the repository: coordinates, bodies, contacts, events,
//! the impact procedure, the step map, the audits, the numerical settings and every choice vrw makes where
//! the paper is silent. Every module cites the section of that file and the paper's equation it implements.
//!
//! The modules follow the pipeline; each imports only the ones above it (`tests/layout.rs` checks this):
//!
//! | stage | module |
//! |---|---|
//! | (beneath the pipeline) the step meter of a grid job's task | [`meter`] |
//! | numerical integration with event location | [`integrate`] |
//! | (beside the pipeline, importing none of the wheel) the continuation engine | [`continuation`] |
//! | parameters and options | [`params`] |
//! | equations of motion, Eq. (1) | [`dynamics`] |
//! | the interface any planar walker gives the engine; its constrained solves; the compass gait | [`mechanism`] |
//! | contacts, stoppers, KKT and impulse solves, Eqs. (2), (5) | [`contact`] |
//! | the hybrid walk: phases, events, the DLS-indicator impact procedure | [`walk`], [`walk::impact`] |
//! | exact derivatives of the step map: variational equations, saltation matrices | [`variational`] |
//! | reference problems with known answers, the default start | [`reference`](mod@reference) |
//! | step map, its exact derivatives, gaits (period 1 and k), Floquet multipliers | [`gait`] |
//! | the wheel's gait as a function of one parameter: its step map as a family, natural continuation | [`family`] |
//! | studies over parameters: the grid runner, sweeps, thresholds, maps and their curves, orbits, basins | [`study`] |
//! | tables and figures | [`output`] |
//! | the command-line jobs | [`app`] |
//!
//! ## What the library promises
//!
//! These are the types and functions to build on, by stage. They are `pub`; so are the methods and fields
//! of these types and the items of the public modules named here.
//!
//! - **Parameters**: [`params::Config`] (the physical [`params::Params`] and the numerical
//!   [`params::SolverOptions`], read from TOML with [`params::Config::load`], changed with
//!   [`params::Config::apply_override`], checked with [`params::Config::validate`]) and
//!   [`params::ConfigError`].
//! - **Model**: [`dynamics::Model`], the equations of motion built from [`params::Params`]; the contact and
//!   impulse solves [`contact::constrained_dynamics`] and [`contact::impulse`].
//! - **Walkers**: the [`mechanism::Mechanism`] interface (the wheel's [`dynamics::Model`] is one, the
//!   [`mechanism::compass::Compass`] gait another), and the force-level and impulse problems of any of them,
//!   [`mechanism::constrained::accelerations`] and [`mechanism::constrained::impulse`].
//! - **Integration**: the [`integrate::OdeSystem`] trait, the [`integrate::Dopri5`] solver with its
//!   [`integrate::DenseStep`] and [`integrate::Tolerances`], and [`integrate::Method`].
//! - **The walk**: [`walk::Walker`] (one step at a time), [`walk::simulate`] and [`walk::simulate_streaming`]
//!   (many steps), each step's [`walk::StepReport`] (the DLS indicators, the energy and contact audits), the
//!   Poincare section state [`walk::SectionState`], the sampled [`walk::Trajectory`] and its
//!   [`walk::SampleSink`], [`walk::WorkCounts`], and [`walk::WalkError`] for a walk that fails.
//! - **Reference problems**: [`reference::RigidRimlessWheel`] (closed-form step map),
//!   [`reference::FallingPoint`], [`reference::HarmonicOscillator`], and the default start
//!   [`reference::default_initial`].
//! - **The gait**: the step map [`gait::StepMap`]; [`gait::find_gait`] with [`gait::GaitOptions`], giving a
//!   [`gait::Gait`] (or a [`gait::GaitError`]); period-k gaits [`gait::find_periodic_gait`] and
//!   [`gait::find_gait_any_period`].
//! - **Families of gaits**: the step map as a family in one parameter [`family::GaitFamily`] (for the engine
//!   below), and the verified natural continuation the sweeps use, [`family::natural`].
//! - **Studies over parameters**: sweeps [`study::sweep()`] over a [`study::SweepSpec`] and their thresholds
//!   [`study::find_thresholds`]; two-parameter maps [`study::map_gaits`] and [`study::map_curves()`]; orbit
//!   diagrams [`study::orbit::orbit_diagram`]; basins of attraction [`study::basin::basin`]; the work and span
//!   of their phases [`study::parallelism`] (measured with a [`meter::StepMeter`] per task).
//! - **Bifurcation analysis**: [`continuation::continue_family`] over any [`continuation::FamilyMap`] (the
//!   VRW's is [`family::GaitFamily`]) with [`continuation::ContinuationOptions`], giving a
//!   [`continuation::Family`] of [`continuation::FamilyPoint`]s with its [`continuation::SpecialPoint`]s and
//!   [`continuation::FamilyEnd`]s; branch switching [`continuation::switch_at_period_doubling`] and
//!   [`continuation::switch_at_border`].
//! - **Output**: the tables [`output::write_steps_csv`], [`output::write_trajectory_csv`] (and the streaming
//!   [`output::StepsCsv`], [`output::TrajectoryCsv`]), [`output::write_sweep_csv`], their headers and rows;
//!   reading a run directory back with [`output::read::read_run`]; the figures
//!   [`output::run_plot::write_run_figure`], [`output::steps_plot::write_steps_figure`] and the animation
//!   [`output::animate::write_animation`].
//! - **Jobs** (what each `vrw` command runs, writing its files into a directory): [`app::run_simulate`],
//!   [`app::run_gait`], [`app::run_sweep`], [`app::run_map`], [`app::run_orbit`], [`app::run_basin`],
//!   [`app::run_plot`], [`app::run_animate`], [`app::run_still`], [`app::run_continuation`], with their job
//!   structs ([`app::SimulateJob`], ...) and [`app::AppError`]; and the jobs that return their results
//!   instead ([`app::compute_simulation`], [`app::compute_gait`], [`app::compute_sweep`],
//!   [`app::compute_continuation`]), which the Python binding uses.
//!
//! Everything else is internal to the crate (`pub(crate)`): the integrator driver and DOP853, the event
//! functions and audits of a step, the grid runner behind sweeps and maps, continuation's tolerances, the
//! table declarations, the charts of the other figures. Internal items may change in any release; the crate
//! warns on a public item that cannot be named (`unnameable_types`), so every type in a public signature is
//! reachable by a public path.
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
//! let start = SectionState::at_rest(0.72, 1.0, 0.0);
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
pub mod continuation;
pub mod dynamics;
pub mod family;
pub mod fmt;
pub mod gait;
pub mod integrate;
pub mod mechanism;
pub mod meter;
pub mod output;
pub mod params;
pub mod reference;
pub mod study;
pub mod variational;
pub mod walk;
