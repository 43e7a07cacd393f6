//! The assembly of a described walker (docs/model.md section 13): every body's frame as a function of `q`,
//! with its Jacobian and velocity product, over any [`Real`], and from them `M`, `h`, the contact points and
//! the energies.
//!
//! A frame is a position `p` with Jacobian `J_p` and `dJ_p/dt q'`, and an angle `beta` (counterclockwise in
//! the slope's `(x, z)` plane) whose Jacobian row `J_beta` is constant (a sum of `+-1` entries of the revolute
//! coordinates). A point `r` fixed in the frame is at `p + R(beta) r`, with
//!
//! ```text
//! J = J_p + R(beta) r_perp J_beta,     dJ/dt q' = dJ_p/dt q' - w^2 R(beta) r,     r_perp = (-r_z, r_x),
//! ```
//!
//! `w = J_beta q'`. A prismatic joint's child is at `r = at + s d` in its parent's frame, which adds `R d` to
//! the column of `s` and the Coriolis term `2 w s' R(beta) d_perp`; a revolute joint's child turns by
//! `+-theta`. Then `M = sum m J_c^T J_c + I J_beta^T J_beta` and `h = sum m J_c^T (dJ_c/dt q' + u)` with
//! `u = g (-sin phi, cos phi)`, plus each spring's `k (s - rest)` and damper's `c s'` on its coordinate: the
//! equations of `super::super::assembly` with rigid bodies and joint forces added.

use nalgebra::{SMatrix, SVector, Vector2};

use super::super::{Equations, PointKinematics, Real};
use super::expr::Expr;
use super::model::{Description, Motion, State, Vector, MAX_PARAMETERS};

/// The parameters' values over a [`Real`]: the constants of a described walker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Values<T: Real> {
    /// By the parameters' order (the first `len` used).
    pub values: [T; MAX_PARAMETERS],
    /// How many.
    pub len: usize,
}

impl<T: Real> Values<T> {
    /// The values in use.
    pub fn as_slice(&self) -> &[T] {
        &self.values[..self.len]
    }

    /// `e`'s value.
    pub fn of(&self, e: &Expr) -> T {
        e.eval(self.as_slice())
    }

    /// A vector's value.
    pub fn vector(&self, v: &Vector) -> Vector2<T> {
        Vector2::new(self.of(&v[0]), self.of(&v[1]))
    }
}

/// A body's frame at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame<T: Real, const N: usize> {
    /// The origin's position, Jacobian and `dJ/dt q'`.
    pub origin: PointKinematics<T, N>,
    /// The angle `beta`.
    pub angle: T,
    /// `J_beta = d beta / dq`.
    pub angle_row: SVector<T, N>,
    /// `w = J_beta q'`.
    pub rate: T,
}

impl<T: Real, const N: usize> Frame<T, N> {
    /// The ground's frame.
    pub fn ground() -> Frame<T, N> {
        Frame {
            origin: PointKinematics {
                position: Vector2::zeros(),
                jacobian: SMatrix::zeros(),
                velocity_product: Vector2::zeros(),
            },
            angle: T::zero(),
            angle_row: SVector::zeros(),
            rate: T::zero(),
        }
    }

    /// `R(beta) r` and `R(beta) r_perp`.
    fn rotated(&self, r: Vector2<T>) -> (Vector2<T>, Vector2<T>) {
        let (s, c) = self.angle.sin_cos();
        let v = Vector2::new(c * r.x - s * r.y, s * r.x + c * r.y);
        (v, Vector2::new(-v.y, v.x))
    }

    /// The point `r` fixed in this frame (see the module documentation).
    pub fn point(&self, r: Vector2<T>) -> PointKinematics<T, N> {
        let (v, perp) = self.rotated(r);
        let w = self.rate;
        PointKinematics {
            position: self.origin.position + v,
            jacobian: self.origin.jacobian + perp * self.angle_row.transpose(),
            velocity_product: self.origin.velocity_product - v * w * w,
        }
    }

    /// The frame of a revolute joint's child at `at`, turned by `sign * (value, rate)` from this frame (or from
    /// the ground's, `absolute`), the value being coordinate `column` if free.
    fn revolute(
        &self,
        at: Vector2<T>,
        (absolute, sign): (bool, T),
        (value, rate): (T, T),
        column: Option<usize>,
    ) -> Frame<T, N> {
        let (base_angle, mut angle_row, base_rate) = if absolute {
            (T::zero(), SVector::zeros(), T::zero())
        } else {
            (self.angle, self.angle_row, self.rate)
        };
        if let Some(k) = column {
            angle_row[k] += sign;
        }
        Frame {
            origin: self.point(at),
            angle: base_angle + sign * value,
            angle_row,
            rate: base_rate + sign * rate,
        }
    }

    /// The frame of a prismatic joint's child, at `at + value d` in this frame, moving at `rate` along `d`, the
    /// value being coordinate `column` if free.
    fn prismatic(
        &self,
        at: Vector2<T>,
        d: Vector2<T>,
        (value, rate): (T, T),
        column: Option<usize>,
    ) -> Frame<T, N> {
        let mut origin = self.point(at + d * value);
        let (along, perp) = self.rotated(d);
        if let Some(k) = column {
            origin.jacobian[(0, k)] += along.x;
            origin.jacobian[(1, k)] += along.y;
        }
        origin.velocity_product += perp * (lit::<T>(2.0) * self.rate * rate);
        Frame {
            origin,
            angle: self.angle,
            angle_row: self.angle_row,
            rate: self.rate,
        }
    }
}

/// The constant `x`.
fn lit<T: Real>(x: f64) -> T {
    T::lit(x)
}

/// `u = g (-sin phi, cos phi)`.
pub fn up<T: Real>(d: &Description, c: &Values<T>) -> Vector2<T> {
    let [slope, gravity] = d.slope_gravity;
    super::super::assembly::up(c.values[gravity], c.values[slope])
}

/// Every body's frame at `(q, q')`, by body index.
pub fn frames<T: Real, const N: usize>(
    d: &Description,
    c: &Values<T>,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> Vec<Frame<T, N>> {
    let mut frames = vec![Frame::ground(); d.bodies.len()];
    for joint in &d.joints {
        let parent = joint.parent.map_or_else(Frame::ground, |p| frames[p]);
        let (value, rate, column) = match &joint.state {
            State::Free(f) => (q[f.coordinate], qd[f.coordinate], Some(f.coordinate)),
            State::Fixed(v) => (c.of(v), T::zero(), None),
        };
        let at = c.vector(&joint.at);
        frames[joint.child] = match &joint.motion {
            Motion::Revolute { absolute, sign } => {
                parent.revolute(at, (*absolute, lit(*sign)), (value, rate), column)
            }
            Motion::Prismatic { direction } => {
                parent.prismatic(at, c.vector(direction), (value, rate), column)
            }
        };
    }
    frames
}

/// `M` and `h` at `(q, q')` (see the module documentation).
pub fn equations<T: Real, const N: usize>(
    d: &Description,
    c: &Values<T>,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> Equations<T, N> {
    let u = up(d, c);
    let mut mass = SMatrix::<T, N, N>::zeros();
    let mut bias = SVector::<T, N>::zeros();
    for (body, frame) in d.bodies.iter().zip(frames(d, c, q, qd)) {
        let (m, inertia) = (c.of(&body.mass), c.of(&body.inertia));
        let centre = frame.point(c.vector(&body.centre));
        let j = &centre.jacobian;
        mass += j.transpose() * j * m;
        bias += j.transpose() * ((centre.velocity_product + u) * m);
        mass += frame.angle_row * frame.angle_row.transpose() * inertia;
    }
    for (_, free) in d.free_joints() {
        let k = free.coordinate;
        if let Some((stiffness, rest)) = &free.spring {
            bias[k] += c.of(stiffness) * (q[k] - c.of(rest));
        }
        if let Some(damper) = &free.damper {
            bias[k] += c.of(damper) * qd[k];
        }
    }
    Equations { mass, bias }
}

/// Contact point `i` at `(q, q')`.
pub fn contact<T: Real, const N: usize>(
    d: &Description,
    c: &Values<T>,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    i: usize,
) -> PointKinematics<T, N> {
    let point = &d.contacts[i];
    frames(d, c, q, qd)[point.body].point(c.vector(&point.at))
}

/// `V`: gravity's `sum m u . p_c` and the springs' `1/2 k (s - rest)^2` \[J\].
pub fn potential_energy<const N: usize>(
    d: &Description,
    c: &Values<f64>,
    q: &SVector<f64, N>,
) -> f64 {
    let u = up(d, c);
    let zero = SVector::zeros();
    let gravity: f64 = d
        .bodies
        .iter()
        .zip(frames(d, c, q, &zero))
        .map(|(body, frame)| {
            c.of(&body.mass) * u.dot(&frame.point(c.vector(&body.centre)).position)
        })
        .sum();
    let springs: f64 = d
        .free_joints()
        .filter_map(|(_, f)| {
            let (stiffness, rest) = f.spring.as_ref()?;
            let stretch = q[f.coordinate] - c.of(rest);
            Some(0.5 * c.of(stiffness) * stretch * stretch)
        })
        .sum();
    gravity + springs
}

/// The dampers' power `sum c s'^2` \[W\].
pub fn damper_power<const N: usize>(d: &Description, c: &Values<f64>, qd: &SVector<f64, N>) -> f64 {
    d.free_joints()
        .filter_map(|(_, f)| {
            let damper = f.damper.as_ref()?;
            Some(c.of(damper) * qd[f.coordinate] * qd[f.coordinate])
        })
        .sum()
}
