//! A described walker on the walker jobs (`simulate`, `sweep`, `orbit`, `plot`, `animate`;
//! docs/model.md section 13): the names of its coordinates, its energies, its slope, and its drawing
//! ([`crate::mechanism::described::Drawing`]: its masses, contacts, hinges and springs), for
//! [`super::walker_model`]'s rigid-leg model and [`super::legged`]'s compliant-leg one.

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
            springs: drawing.springs,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::Walker;
    use crate::mechanism::described::AnyDescribed;
    use crate::mechanism::telescopic::Telescopic;

    /// The walker of the description `models/NAME.toml`.
    fn shipped(name: &str) -> Walker {
        let path = format!("{}/models/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        Walker::load(&path, None, &[] as &[&str]).unwrap().unwrap()
    }

    /// A described walker's sprung joints are drawn as springs: `models/telescopic.toml`'s figure (what its runs'
    /// `summary.json` declares) has a coil per leg, from a sleeve linked to its hinge to a rod linked to its
    /// foot; at the default parameters, where the description's spring ends (half the stopper length below the
    /// hip, a quarter of it above the foot) fall where the built-in telescopic walker puts its sleeves' ends and
    /// rods' tops (`L0 - a`, `a / 2`), they are the built-in's points at every state tried. The compass gait's
    /// description, without springs, has none.
    #[test]
    fn a_described_walkers_springs_are_drawn_as_the_built_in_telescopics() {
        let Walker::Described(AnyDescribed::N6(described)) = shipped("telescopic") else {
            panic!("telescopic.toml has 6 coordinates")
        };
        let figure = shipped("telescopic").model().unwrap().figure();
        assert_eq!(figure, described.stick_figure());
        let names: Vec<[&str; 2]> = figure
            .springs
            .iter()
            .map(|s| s.map(|p| figure.points[p].as_str()))
            .collect();
        assert_eq!(
            names,
            [
                ["L1_spring_top", "L1_spring_bottom"],
                ["L2_spring_top", "L2_spring_bottom"]
            ]
        );
        for (k, [top, bottom]) in figure.springs.iter().enumerate() {
            let hinge = figure
                .points
                .iter()
                .position(|p| *p == format!("theta{}_hinge", k + 1));
            assert!(figure.links.contains(&[hinge.unwrap(), *top]), "{figure:?}");
            assert!(
                figure.links.contains(&[*bottom, figure.feet[k]]),
                "{figure:?}"
            );
        }
        let built_in = Telescopic::default();
        let theirs = built_in.stick_figure();
        for q in [
            [0.0, 0.95, 0.28, -0.28, 1.0, 0.997],
            [-0.31, 0.9, 0.1, -0.4, 0.96, 1.0],
            [0.2, 1.1, -0.35, 0.22, 0.99, 0.93],
        ] {
            let q = SVector::<f64, 6>::from(q);
            let (ours, built) = (described.points(&q), built_in.points(&q));
            for (a, b) in figure.springs.iter().zip(&theirs.springs) {
                for (i, j) in a.iter().zip(b) {
                    let d = (ours[*i][0] - built[*j][0]).hypot(ours[*i][1] - built[*j][1]);
                    assert!(
                        d < 1e-12,
                        "{q:?}: {} against {}: {d:e}",
                        figure.points[*i],
                        theirs.points[*j]
                    );
                }
            }
        }
        assert!(shipped("compass")
            .model()
            .unwrap()
            .figure()
            .springs
            .is_empty());
    }
}
