//! A described walker with rigid legs on the walker jobs (`simulate`, `sweep`, `orbit`, `plot`, `animate`;
//! docs/model.md section 13): the names of its coordinates, its energies, its slope, and its drawing
//! ([`crate::mechanism::described::Drawing`]: its masses, contacts and hinges), for [`super::walker_model`]'s
//! rigid-leg model.

use nalgebra::{DVector, SVector};

use super::walker_model::Body;
use crate::mechanism::described::Described;
use crate::mechanism::Mechanism;
use crate::output::walker_run::StickFigure;

impl<const N: usize> Body<N> for Described<N> {
    fn coordinate_names(&self) -> [&'static str; N] {
        self.coordinates()
    }

    fn kinetic(&self, q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        self.kinetic_energy(q, qd)
    }

    /// The value of the parameter the description names its slope.
    fn slope_angle(&self) -> f64 {
        self.values[self.description.slope_gravity[0]]
    }

    fn stick_figure(&self) -> StickFigure {
        let drawing = self.drawing();
        StickFigure {
            points: drawing.points,
            links: drawing.links,
            masses: drawing.masses,
            feet: drawing.contacts,
            springs: Vec::new(),
        }
    }

    fn points(&self, q: &SVector<f64, N>) -> Vec<[f64; 2]> {
        self.drawing_points(q)
    }
}

/// The start of its `[gait]` table (the jobs check that it walks before they take it: [`super::Walker::model`]).
pub(super) fn described_start<const N: usize>(w: &Described<N>) -> DVector<f64> {
    w.description.gait.as_ref().map_or_else(
        || DVector::zeros(0),
        |g| DVector::from_column_slice(&g.start),
    )
}
