//! Clipping to a plotting area ([`Clip`]): every curve, band, marker and reference line a figure draws inside
//! a panel goes through it, so that nothing crosses the panel's frame. plotters draws whatever it is given
//! anywhere on the canvas, so the figures clip their shapes themselves: polylines segment by segment
//! (Liang-Barsky), filled shapes as polygons (Sutherland-Hodgman), rectangles by their corners. Shapes that
//! lie inside are drawn exactly as before.
//!
//! Thick polylines are also split where they turn back sharply ([`split_sharp_turns`]): plotters joins the
//! segments of a line wider than one pixel with a mitre whose inner corner it does not bound, so a curve that
//! jumps (a force at a contact event) and then steps one pixel back draws a spike hundreds of pixels long.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{dashed_with, draw_marker, DrawResult, Marker};

/// Sides of the polygon that stands for a circle cut by the frame.
const CIRCLE_SIDES: usize = 48;

/// The cosine of the sharpest join plotters draws without a spike: its mitre's inner corner lies
/// `half width / sin(angle / 2)` from the point, which it caps at 4 half widths on the outer side only, so a
/// join of interior angle below `2 asin(1/4)` (29 degrees) is split. `cos(2 asin(1/4)) = 1 - 2 / 16`.
const SHARP_COS: f64 = 1.0 - 2.0 / 16.0;

/// A pixel rectangle, inclusive on all sides, in the coordinates of the drawing area it clips.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clip {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

type Pt = (f64, f64);
type Px = (i32, i32);
/// One side of the rectangle for Sutherland-Hodgman: whether a point is inside it, and where a segment
/// crosses it.
type Side = (fn(&Clip, Pt) -> bool, fn(&Clip, Pt, Pt) -> Pt);

fn to_f(p: (i32, i32)) -> Pt {
    (f64::from(p.0), f64::from(p.1))
}

fn to_i(p: Pt) -> (i32, i32) {
    (p.0.round() as i32, p.1.round() as i32)
}

impl Clip {
    /// The pixel columns `x` and rows `y` (end exclusive).
    pub fn new(x: Range<i32>, y: Range<i32>) -> Clip {
        Clip {
            x0: f64::from(x.start),
            y0: f64::from(y.start),
            x1: f64::from(x.end - 1),
            y1: f64::from(y.end - 1),
        }
    }

    /// The whole of `area`.
    pub fn of_area<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> Clip {
        let (w, h) = area.dim_in_pixel();
        Clip::new(0..w as i32, 0..h as i32)
    }

    /// Whether the pixel `p` is inside.
    pub fn contains(&self, p: (i32, i32)) -> bool {
        let (x, y) = to_f(p);
        (self.x0..=self.x1).contains(&x) && (self.y0..=self.y1).contains(&y)
    }

    /// Whether the square of half side `r` around `p` is inside.
    fn holds(&self, p: (i32, i32), r: i32) -> bool {
        self.contains((p.0 - r, p.1 - r)) && self.contains((p.0 + r, p.1 + r))
    }

    /// The part of the segment `a`-`b` inside (Liang-Barsky), `None` if there is none.
    pub fn segment(&self, a: Pt, b: Pt) -> Option<(Pt, Pt)> {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
        (t0 <= t1).then(|| {
            let start = if t0 > 0.0 { at(t0) } else { a };
            let end = if t1 < 1.0 { at(t1) } else { b };
            (start, end)
        })
    }

    /// The pieces of the polyline `pts` inside: a piece ends where the line leaves the rectangle. Points
    /// inside keep their pixels; the line's crossings of the frame become new end points.
    pub fn polyline(&self, pts: &[(i32, i32)]) -> Vec<Vec<(i32, i32)>> {
        let mut out: Vec<Vec<(i32, i32)>> = Vec::new();
        if let [p] = pts {
            if self.contains(*p) {
                out.push(vec![*p]);
            }
        }
        let mut open = false; // the last piece ends at the previous point
        for seg in pts.windows(2) {
            match self.segment(to_f(seg[0]), to_f(seg[1])) {
                Some((a, b)) => {
                    let (a, b) = (to_i(a), to_i(b));
                    match out.last_mut() {
                        Some(piece) if open && a == seg[0] => piece.push(b),
                        _ => out.push(vec![a, b]),
                    }
                    open = b == seg[1];
                }
                None => open = false,
            }
        }
        out
    }

    /// The convex polygon `pts` cut to the rectangle (Sutherland-Hodgman), in pixels.
    pub fn polygon(&self, pts: &[Pt]) -> Vec<(i32, i32)> {
        let sides: [Side; 4] = [
            (|c, p| p.0 >= c.x0, |c, a, b| cut_x(a, b, c.x0)),
            (|c, p| p.0 <= c.x1, |c, a, b| cut_x(a, b, c.x1)),
            (|c, p| p.1 >= c.y0, |c, a, b| cut_y(a, b, c.y0)),
            (|c, p| p.1 <= c.y1, |c, a, b| cut_y(a, b, c.y1)),
        ];
        let mut poly = pts.to_vec();
        for (inside, cut) in sides {
            let input = std::mem::take(&mut poly);
            for (k, &b) in input.iter().enumerate() {
                let a = input[(k + input.len() - 1) % input.len()];
                match (inside(self, a), inside(self, b)) {
                    (true, true) => poly.push(b),
                    (true, false) => poly.push(cut(self, a, b)),
                    (false, true) => {
                        poly.push(cut(self, a, b));
                        poly.push(b);
                    }
                    (false, false) => {}
                }
            }
        }
        poly.into_iter().map(to_i).collect()
    }

    /// The rectangle with corners `a` and `b` cut to the clip (`None` if they do not overlap).
    pub fn rect(&self, a: (i32, i32), b: (i32, i32)) -> Option<[(i32, i32); 2]> {
        let (x0, x1) = (a.0.min(b.0), a.0.max(b.0));
        let (y0, y1) = (a.1.min(b.1), a.1.max(b.1));
        let (cx0, cy0, cx1, cy1) = (
            self.x0 as i32,
            self.y0 as i32,
            self.x1 as i32,
            self.y1 as i32,
        );
        if x1 < cx0 || x0 > cx1 || y1 < cy0 || y0 > cy1 {
            return None;
        }
        if x0 >= cx0 && x1 <= cx1 && y0 >= cy0 && y1 <= cy1 {
            return Some([a, b]);
        }
        Some([(x0.max(cx0), y0.max(cy0)), (x1.min(cx1), y1.min(cy1))])
    }

    /// Draws the polyline `pts` on `area` in `style`, clipped, and split where it turns back sharply.
    pub fn draw_path<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        pts: &[(i32, i32)],
        style: ShapeStyle,
    ) -> DrawResult<DB> {
        for piece in self.polyline(pts) {
            if style.stroke_width > 1 {
                for part in split_sharp_turns(&piece) {
                    area.draw(&PathElement::new(part, style))?;
                }
            } else {
                area.draw(&PathElement::new(piece, style))?;
            }
        }
        Ok(())
    }

    /// Draws the polyline `pts` dashed (`dash`, `gap` pixels) on `area`, clipped.
    pub fn draw_dashed<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        pts: &[(i32, i32)],
        style: ShapeStyle,
        dash_gap: (f64, f64),
    ) -> DrawResult<DB> {
        for piece in self.polyline(pts) {
            dashed_with(area, &piece, style, dash_gap)?;
        }
        Ok(())
    }

    /// Draws a circle of radius `r` at `at` (filled or stroked as `style` says), cut to the clip; nothing if
    /// its centre is outside.
    pub fn draw_circle<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        at: (i32, i32),
        r: i32,
        style: ShapeStyle,
    ) -> DrawResult<DB> {
        if !self.contains(at) {
            return Ok(());
        }
        if self.holds(at, r + style.stroke_width as i32) {
            return area.draw(&Circle::new(at, r, style));
        }
        let ring = circle_points(at, f64::from(r));
        if style.filled {
            area.draw(&Polygon::new(self.polygon(&ring), style))
        } else {
            let mut closed: Vec<(i32, i32)> = ring.into_iter().map(to_i).collect();
            closed.push(closed[0]);
            self.draw_path(area, &closed, style)
        }
    }

    /// Draws a [`Marker`] as [`draw_marker`] does, cut to the clip; nothing if its centre is outside.
    pub fn draw_marker<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        at: (i32, i32),
        shape: Marker,
        color: RGBColor,
        hollow: bool,
        r: i32,
    ) -> DrawResult<DB> {
        if !self.contains(at) {
            return Ok(());
        }
        // The triangle reaches r + 2 from its centre, a hollow outline one pixel further.
        if self.holds(at, r + 3) {
            return draw_marker(area, at, shape, color, hollow, r);
        }
        let outline: Vec<Pt> = match shape {
            Marker::Circle => circle_points(at, f64::from(r)),
            Marker::Triangle => {
                let s = r + 2;
                let h = (s as f64 * 0.87).round() as i32;
                [
                    (at.0, at.1 - s),
                    (at.0 - h, at.1 + s / 2),
                    (at.0 + h, at.1 + s / 2),
                ]
                .into_iter()
                .map(to_f)
                .collect()
            }
        };
        let fill = if hollow { WHITE } else { color };
        area.draw(&Polygon::new(self.polygon(&outline), fill.filled()))?;
        if hollow {
            let mut closed: Vec<(i32, i32)> = outline.into_iter().map(to_i).collect();
            closed.push(closed[0]);
            self.draw_path(area, &closed, color.stroke_width(2))?;
        }
        Ok(())
    }

    /// Draws the rectangle with corners `a`, `b` in `style`, cut to the clip.
    pub fn draw_rect<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        [a, b]: [(i32, i32); 2],
        style: ShapeStyle,
    ) -> DrawResult<DB> {
        match self.rect(a, b) {
            Some(corners) => area.draw(&Rectangle::new(corners, style)),
            None => Ok(()),
        }
    }
}

fn cut_x(a: Pt, b: Pt, x: f64) -> Pt {
    (x, a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0))
}

fn cut_y(a: Pt, b: Pt, y: f64) -> Pt {
    (a.0 + (b.0 - a.0) * (y - a.1) / (b.1 - a.1), y)
}

/// A polygon of [`CIRCLE_SIDES`] sides around a circle.
fn circle_points(at: (i32, i32), r: f64) -> Vec<Pt> {
    (0..CIRCLE_SIDES)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / CIRCLE_SIDES as f64;
            (f64::from(at.0) + r * a.cos(), f64::from(at.1) + r * a.sin())
        })
        .collect()
}

/// The polyline `pts` split at every join sharper than plotters' mitre can draw (an interior angle below
/// 29 degrees, see the module comment); the
/// parts share the point where they meet. A polyline without such a join comes back whole.
pub fn split_sharp_turns(pts: &[(i32, i32)]) -> Vec<Vec<(i32, i32)>> {
    let mut out = vec![Vec::new()];
    // The last two distinct points of the current part.
    let (mut before, mut last): (Option<Px>, Option<Px>) = (None, None);
    for &p in pts {
        if let (Some(a), Some(b)) = (before, last) {
            if p != b && sharp(a, b, p) {
                out.push(vec![b]);
                before = None;
            }
        }
        if last != Some(p) {
            if last.is_some() {
                before = last;
            }
            last = Some(p);
        }
        if let Some(part) = out.last_mut() {
            part.push(p);
        }
    }
    out
}

/// Whether the join at `b` of the segments from `a` and to `c` has an interior angle below 29 degrees (but
/// does not fold straight back, which plotters draws without a spike).
fn sharp(a: (i32, i32), b: (i32, i32), c: (i32, i32)) -> bool {
    let u = (f64::from(a.0 - b.0), f64::from(a.1 - b.1));
    let v = (f64::from(c.0 - b.0), f64::from(c.1 - b.1));
    let cross = u.0 * v.1 - u.1 * v.0;
    let cos = (u.0 * v.0 + u.1 * v.1) / (u.0.hypot(u.1) * v.0.hypot(v.1));
    cross != 0.0 && cos > SHARP_COS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_segment_that_leaves_the_area_is_cut_at_the_frame() {
        let clip = Clip::new(0..101, 0..51);
        let pieces = clip.polyline(&[(10, 10), (50, 40), (50, 200), (60, 40), (70, 30)]);
        assert_eq!(
            pieces,
            vec![
                vec![(10, 10), (50, 40), (50, 50)],
                vec![(59, 50), (60, 40), (70, 30)]
            ]
        );
        assert!(clip.polyline(&[(-5, -5), (-1, 200)]).is_empty());
        assert_eq!(clip.polyline(&[(1, 1), (2, 2)]), vec![vec![(1, 1), (2, 2)]]);
    }

    #[test]
    fn a_force_jump_that_steps_back_splits_the_line() {
        // The run figure's lambda_1 at t = 16.28 s: a jump of 81 px up, then one pixel back down.
        let pts = [
            (602, 1790),
            (603, 1786),
            (604, 1705),
            (604, 1706),
            (605, 1707),
        ];
        assert_eq!(
            split_sharp_turns(&pts),
            vec![
                vec![(602, 1790), (603, 1786), (604, 1705)],
                vec![(604, 1705), (604, 1706), (605, 1707)]
            ]
        );
        let smooth = [(0, 0), (1, 2), (2, 3), (2, 3), (3, 3), (4, 2)];
        assert_eq!(split_sharp_turns(&smooth), vec![smooth.to_vec()]);
    }

    #[test]
    fn a_polygon_is_cut_to_the_rectangle() {
        let clip = Clip::new(0..11, 0..11);
        let cut = clip.polygon(&[(5.0, 5.0), (15.0, 5.0), (15.0, 8.0), (5.0, 8.0)]);
        assert!(cut.iter().all(|&p| clip.contains(p)));
        assert!(cut.contains(&(10, 5)) && cut.contains(&(10, 8)));
        assert_eq!(clip.rect((-3, 2), (4, 20)), Some([(0, 2), (4, 10)]));
        assert_eq!(clip.rect((12, 2), (14, 20)), None);
    }
}
