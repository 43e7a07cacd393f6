//! The grid runner: evaluate something at every point of a grid of rows, each row continued from left to right,
//! rows in parallel, with results bitwise identical for any number of threads.
//!
//! Sweeps and maps ([`super::sweep::gait_rows_measured`]) and any other "evaluate the step map over a grid, continuing
//! along rows" job use this one runner. A job supplies the evaluation of one point as a closure
//! `eval(cell, from) -> Evaluated { point, carry }`:
//!
//! - `cell` is the point's place in the grid (row and column);
//! - `from` is `Some((col, carry))` when the point continues an earlier point of the same row: `col` is that
//!   point's column (always to the left) and `carry` what its evaluation handed on (a gait, a state, ...); `None`
//!   for the first point of a row, or when the point continued from handed on nothing;
//! - `carry` is what later points may continue from (`None`: nothing, e.g. no gait was found).
//!
//! **Schedule.** A grid of several rows runs its rows in parallel, each row in order from left to right, every
//! point continuing its left neighbour. A grid of one row (a sweep, an orbit diagram) is split so that it too
//! uses every core: first every [`COARSE_STRIDE`]-th point is evaluated in order, each continuing the previous
//! coarse point (the coarse pass); then the points between two coarse points are evaluated in order, continuing
//! from the left coarse point, all intervals in parallel, the one whose coarse step took longest first (the
//! interval with a family's end in it brackets that end, and started last it made the run's tail; the order of
//! the work is the only thing the clock decides). (A coarse pass costs extra work, continuation over ten
//! grid intervals at a time: a fifth of a 30 x 30 map's gait search, so rows that can run in parallel anyway
//! skip it.) The schedule is fixed by the grid, not by the threads, and a point's evaluation depends only on its
//! cell and on what it continues, so as long as `eval` is a deterministic function of its arguments the results
//! do not depend on the number of threads or on the order in which rayon runs the work.
//!
//! **Measured parallelism.** Every point's evaluation is a task, run under a step meter and timed
//! ([`super::parallelism`]); the runner returns with the points the graph of these tasks as its schedule orders
//! them (`run_rows_measured`), from which a job reports its work and span.
//!
//! **Interruption.** The runner checks the library's interrupt flag ([`interrupt_flag`], set by the command
//! line's Ctrl-C handler and by the Python binding's signal watcher) before every point and after it. Once it
//! is set, no new point starts; the points under way stop (their walks read the flag too) and are dropped,
//! and every row is cut to its complete prefix (the points from its first up to the first one not evaluated
//! before the flag was set), so what is returned is exactly what an uninterrupted
//! run returns, minus the rows' tails. A job that sees [`crate::walk::interrupted`] after the runner keeps those points and
//! says it was interrupted.
//!
//! The example of a running sum along each row is the test `running_sum_along_rows` below (the runner is
//! internal to the crate, so it is not a doc test).

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::parallelism::{measured, Cost, TaskGraph};
use crate::meter::carried;
use crate::walk::interrupt::interrupt_flag;

/// Stride of the coarse continuation pass along a row.
pub(crate) const COARSE_STRIDE: usize = 10;

/// A point's place in the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) struct Cell {
    /// Row index, from 0.
    pub row: usize,
    /// Column index along the row, from 0.
    pub col: usize,
}

/// The result of one point's evaluation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Evaluated<P, C> {
    /// The point's result, returned by [`run_rows`].
    pub point: P,
    /// What later points of the row may continue from; `None` if nothing (they then start afresh).
    pub carry: Option<C>,
}

/// The points of a grid run and its task graph ([`super::parallelism`]): one task per point, after the point
/// it continues from on the schedule (in a row in order, after the point before, whether or not that handed
/// anything on: the schedule waits for it).
#[derive(Debug, Clone)]
pub(crate) struct GridRun<P> {
    /// The points, row by row, as [`run_rows`] returns them.
    pub rows: Vec<Vec<P>>,
    /// One task per point.
    pub graph: TaskGraph,
    /// For each row (in the order of `rows`), the node of `graph` at which all its points are done.
    pub row_done: Vec<usize>,
}

/// Evaluate every point of a grid of `rows` rows of `cols` points each, continuing along rows (see the module
/// documentation for the schedule). Returns the points row by row, in column order; once the library's
/// [`interrupt_flag`] is set, rows are cut to their complete prefix. `eval` must be a deterministic function of
/// its arguments for the results to be the same for any number of threads.
pub fn run_rows<P, C, F>(rows: usize, cols: usize, eval: F) -> Vec<Vec<P>>
where
    P: Send,
    C: Send + Sync,
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C> + Sync,
{
    run_part_until(0..rows, rows, cols, interrupt_flag(), eval).rows
}

/// [`run_rows`] stopped by `stop` instead of the library's interrupt flag.
#[cfg(test)]
pub fn run_rows_until<P, C, F>(rows: usize, cols: usize, stop: &AtomicBool, eval: F) -> Vec<Vec<P>>
where
    P: Send,
    C: Send + Sync,
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C> + Sync,
{
    run_part_until(0..rows, rows, cols, stop, eval).rows
}

/// The rows `part` of a grid of `rows` rows (a chunk of a study spread over processes, see
/// [`super::map::map_gaits_measured`]): every point of these rows exactly as [`run_rows`] computes it for the
/// whole grid (the schedule is the whole grid's: a grid of one row is split, the rows of a larger one run in
/// order), returned in the order of `part`, with the task graph. `part` must lie within `0..rows`.
pub(crate) fn run_rows_measured<P, C, F>(
    part: Range<usize>,
    rows: usize,
    cols: usize,
    eval: F,
) -> GridRun<P>
where
    P: Send,
    C: Send + Sync,
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C> + Sync,
{
    run_part_until(part, rows, cols, interrupt_flag(), eval)
}

/// The rows `part` of a grid whose points continue nothing (each starts afresh, as a basin's do): every point
/// in parallel, each exactly as [`run_rows_measured`] computes it, with the task graph (independent tasks). Rows
/// are cut to their complete prefix once the library's [`interrupt_flag`] is set.
pub(crate) fn run_independent<P, F>(part: Range<usize>, cols: usize, eval: F) -> GridRun<P>
where
    P: Send,
    F: Fn(Cell) -> P + Sync,
{
    let stop = interrupt_flag();
    let cells: Vec<Cell> = part
        .clone()
        .flat_map(|row| (0..cols).map(move |col| Cell { row, col }))
        .collect();
    let points: Vec<Option<(P, Cost)>> = cells
        .par_iter()
        .map(carried(|&cell: &Cell| {
            if stopped(stop) {
                return None;
            }
            let out = measured(|| eval(cell));
            (!stopped(stop)).then_some(out)
        }))
        .collect();
    let mut points = points.into_iter();
    let mut run = GridRun {
        rows: Vec::with_capacity(part.len()),
        graph: TaskGraph::new(),
        row_done: Vec::with_capacity(part.len()),
    };
    for _ in part {
        let cells: Vec<Option<(P, Cost)>> = points.by_ref().take(cols).collect();
        // The complete prefix.
        let row: Vec<(P, Cost)> = cells.into_iter().map_while(|p| p).collect();
        let nodes: Vec<usize> = row.iter().map(|p| run.graph.task(p.1, &[])).collect();
        run.row_done.push(run.graph.join(&nodes));
        run.rows.push(row.into_iter().map(|p| p.0).collect());
    }
    run
}

fn run_part_until<P, C, F>(
    part: Range<usize>,
    rows: usize,
    cols: usize,
    stop: &AtomicBool,
    eval: F,
) -> GridRun<P>
where
    P: Send,
    C: Send + Sync,
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C> + Sync,
{
    debug_assert!(part.end <= rows, "rows {part:?} of a grid of {rows}");
    let split = rows == 1;
    let costed: Vec<Vec<(P, Cost)>> = match split {
        true => part
            .map(|row| run_split_row(row, cols, stop, &eval))
            .collect(),
        false => part
            .into_par_iter()
            .map(carried(|row| run_row_in_order(row, cols, stop, &eval)))
            .collect(),
    };
    let mut graph = TaskGraph::new();
    let mut row_done = Vec::with_capacity(costed.len());
    let rows = costed
        .into_iter()
        .map(|row| {
            let costs: Vec<Cost> = row.iter().map(|p| p.1).collect();
            row_done.push(schedule(&mut graph, &costs, split));
            row.into_iter().map(|p| p.0).collect()
        })
        .collect();
    GridRun {
        rows,
        graph,
        row_done,
    }
}

/// Add the tasks of one row's points (their `costs`, in column order) to `graph` as the schedule runs them
/// (`split`: the coarse pass and the fills, else in order); the node at which the row is done.
fn schedule(graph: &mut TaskGraph, costs: &[Cost], split: bool) -> usize {
    let mut ends = Vec::new();
    let mut coarse: Option<usize> = None;
    let mut last: Option<usize> = None;
    for (col, &cost) in costs.iter().enumerate() {
        let after = match (split, col % COARSE_STRIDE == 0) {
            (true, true) => coarse,
            (true, false) if col % COARSE_STRIDE == 1 => coarse,
            _ => last,
        };
        let node = graph.task(cost, after.as_slice());
        if split && col % COARSE_STRIDE == 0 {
            coarse = Some(node);
            ends.push(node);
        }
        if split && (col + 1) % COARSE_STRIDE == 0 {
            ends.push(node);
        }
        last = Some(node);
    }
    ends.extend(last);
    graph.join(&ends)
}

/// Has the run been stopped? Checked before a point starts and again after it returns: a point whose
/// evaluation overlapped the flag may have had its walks cut short (they read the library's flag too), so it
/// is dropped with the rest of its row, never kept as a result.
fn stopped(stop: &AtomicBool) -> bool {
    stop.load(Ordering::Relaxed)
}

/// One point's evaluation as a task: the evaluation and what it cost.
fn eval_task<P, C, F>(eval: &F, cell: Cell, from: Option<(usize, &C)>) -> (Evaluated<P, C>, Cost)
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    measured(|| eval(cell, from))
}

/// One row in order, every point continuing the one before; each point with its cost.
fn run_row_in_order<P, C, F>(row: usize, cols: usize, stop: &AtomicBool, eval: &F) -> Vec<(P, Cost)>
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    let mut points = Vec::with_capacity(cols);
    let mut last: Option<(usize, C)> = None;
    for col in 0..cols {
        if stopped(stop) {
            break;
        }
        let (e, cost) = eval_task(eval, Cell { row, col }, last.as_ref().map(|(j, c)| (*j, c)));
        if stopped(stop) {
            break;
        }
        points.push((e.point, cost));
        last = e.carry.map(|c| (col, c));
    }
    points
}

/// One row split for parallelism: the coarse pass, then the intervals between coarse points in parallel; each
/// point with its cost.
fn run_split_row<P, C, F>(row: usize, cols: usize, stop: &AtomicBool, eval: &F) -> Vec<(P, Cost)>
where
    P: Send,
    C: Send + Sync,
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C> + Sync,
{
    let (coarse_points, carries) = coarse_pass_until(row, cols, stop, eval);
    // The intervals are independent: they start longest first, each as long as the coarse step over it took
    // (the one with a family's end in it takes the longest, and started last it was the wall time's tail).
    // Only the order of the work depends on the clock, never a result.
    let took = |k: usize| coarse_points.get(k + 1).map_or(0.0, |p| p.1.seconds);
    let mut order: Vec<usize> = (0..carries.len()).collect();
    order.sort_by(|&a, &b| took(b).total_cmp(&took(a)));
    let mut fills: Vec<(usize, Vec<(P, Cost)>)> = order
        .into_par_iter()
        .with_max_len(1)
        .map(carried(|k| {
            (k, fill_until(row, cols, k, carries[k].as_ref(), stop, eval))
        }))
        .collect();
    fills.sort_by_key(|(k, _)| *k);
    let fills = fills.into_iter().map(|(_, fill)| fill);
    // The complete prefix: stop after the first interval whose fill was cut short (or before a coarse point
    // that was never evaluated).
    let mut points = Vec::with_capacity(cols);
    for (k, (left, fill)) in coarse_points.into_iter().zip(fills).enumerate() {
        let cut = fill.len() < fill_len(cols, k);
        points.push(left);
        points.extend(fill);
        if cut {
            break;
        }
    }
    points
}

/// The number of points between coarse point `k` and the next (or the row's end).
pub(crate) fn fill_len(cols: usize, k: usize) -> usize {
    let first = k * COARSE_STRIDE;
    (first + COARSE_STRIDE).min(cols).saturating_sub(first + 1)
}

/// The coarse pass of a split row (see the module documentation): every [`COARSE_STRIDE`]-th point in order,
/// each continuing the previous coarse point; their points and what each hands on, in order. Stops starting
/// points once the library's [`interrupt_flag`] is set. With [`fill`], the parts of a split row computed
/// apart (a study spread over processes): the row is the coarse points with the fills between them.
pub(crate) fn coarse_pass<P, C, F>(row: usize, cols: usize, eval: &F) -> (Vec<P>, Vec<Option<C>>)
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    let (points, carries) = coarse_pass_until(row, cols, interrupt_flag(), eval);
    (points.into_iter().map(|p| p.0).collect(), carries)
}

/// [`coarse_pass`] stopped by `stop`, each point with its cost.
#[allow(clippy::type_complexity)]
fn coarse_pass_until<P, C, F>(
    row: usize,
    cols: usize,
    stop: &AtomicBool,
    eval: &F,
) -> (Vec<(P, Cost)>, Vec<Option<C>>)
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    let n = cols.div_ceil(COARSE_STRIDE);
    let mut points = Vec::with_capacity(n);
    let mut carries: Vec<Option<C>> = Vec::with_capacity(n);
    for col in (0..cols).step_by(COARSE_STRIDE) {
        if stopped(stop) {
            break;
        }
        let from = carries
            .last()
            .and_then(|c| c.as_ref().map(|c| (col - COARSE_STRIDE, c)));
        let (e, cost) = eval_task(eval, Cell { row, col }, from);
        if stopped(stop) {
            break;
        }
        points.push((e.point, cost));
        carries.push(e.carry);
    }
    (points, carries)
}

/// The points between coarse point `k` (which handed on `left`) and the next, in order, each continuing the
/// one before (see [`coarse_pass`]). Stops starting points once the library's [`interrupt_flag`] is set.
pub(crate) fn fill<P, C, F>(row: usize, cols: usize, k: usize, left: Option<&C>, eval: &F) -> Vec<P>
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    let points = fill_until(row, cols, k, left, interrupt_flag(), eval);
    points.into_iter().map(|p| p.0).collect()
}

fn fill_until<P, C, F>(
    row: usize,
    cols: usize,
    k: usize,
    left: Option<&C>,
    stop: &AtomicBool,
    eval: &F,
) -> Vec<(P, Cost)>
where
    F: Fn(Cell, Option<(usize, &C)>) -> Evaluated<P, C>,
{
    let first = k * COARSE_STRIDE;
    let mut last: Option<(usize, Option<C>)> = None;
    let mut points = Vec::with_capacity(fill_len(cols, k));
    for col in first + 1..first + 1 + fill_len(cols, k) {
        if stopped(stop) {
            break;
        }
        let from = match &last {
            None => left.map(|c| (first, c)),
            Some((j, c)) => c.as_ref().map(|c| (*j, c)),
        };
        let (e, cost) = eval_task(eval, Cell { row, col }, from);
        if stopped(stop) {
            break;
        }
        points.push((e.point, cost));
        last = Some((col, e.carry));
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each point records what it continued from: the schedule is the documented one, split into a coarse
    /// pass and fills for one row, in order for several.
    #[test]
    fn points_continue_the_documented_neighbour() {
        let cols = 2 * COARSE_STRIDE + 3;
        // Column COARSE_STRIDE + 2 hands on nothing.
        let eval = |cell: Cell, from: Option<(usize, &usize)>| Evaluated {
            point: (cell, from.map(|(j, c)| (j, *c))),
            carry: (cell.col != COARSE_STRIDE + 2).then_some(cell.col),
        };
        for (rows, split) in [(1, true), (3, false)] {
            let grid = run_rows(rows, cols, eval);
            assert_eq!(grid.len(), rows);
            for (r, row) in grid.iter().enumerate() {
                assert_eq!(row.len(), cols);
                for (col, (cell, from)) in row.iter().enumerate() {
                    assert_eq!(*cell, Cell { row: r, col });
                    let expected = match col {
                        0 => None,
                        // The point after the one that hands on nothing starts afresh.
                        c if c == COARSE_STRIDE + 3 => None,
                        c if split && c % COARSE_STRIDE == 0 => Some(c - COARSE_STRIDE),
                        c => Some(c - 1),
                    };
                    assert_eq!(from.map(|(j, _)| j), expected, "{rows} rows, col {col}");
                    if let Some((j, c)) = from {
                        assert_eq!(j, c);
                    }
                }
            }
        }
    }

    /// A stop flag set during the run cuts every row to its complete prefix, without the point under way, for
    /// one row (split) and for several.
    #[test]
    fn interrupted_grid_keeps_complete_prefixes() {
        let cols = 3 * COARSE_STRIDE + 4;
        for rows in [1, 3] {
            let stop = AtomicBool::new(false);
            let grid = run_rows_until(rows, cols, &stop, |cell: Cell, _: Option<(usize, &())>| {
                if cell.col == 2 * COARSE_STRIDE + 5 {
                    stop.store(true, Ordering::SeqCst);
                }
                Evaluated {
                    point: cell.col,
                    carry: Some(()),
                }
            });
            for row in &grid {
                assert!(row.len() < cols, "{rows} rows: {row:?}");
                assert!(row.iter().copied().eq(0..row.len()), "{rows} rows: {row:?}");
                // The point under way when the flag was set is not a result.
                assert!(row.len() <= 2 * COARSE_STRIDE + 5, "{rows} rows: {row:?}");
            }
        }
        let stop = AtomicBool::new(true);
        let grid = run_rows_until(2, 5, &stop, |cell: Cell, _: Option<(usize, &())>| {
            Evaluated {
                point: cell,
                carry: None,
            }
        });
        assert!(grid.iter().all(Vec::is_empty));
    }

    /// Rows of one point, and an empty grid.
    #[test]
    fn degenerate_grids() {
        let eval = |cell: Cell, _: Option<(usize, &())>| Evaluated {
            point: cell,
            carry: None,
        };
        assert_eq!(
            run_rows(2, 1, eval),
            vec![vec![Cell { row: 0, col: 0 }], vec![Cell { row: 1, col: 0 }]]
        );
        assert!(run_rows(0, 5, eval).is_empty());
        assert_eq!(run_rows(1, 0, eval), vec![Vec::<Cell>::new()]);
    }

    /// A part of a grid is those rows of the whole grid, point for point, for one row (split) and several.
    #[test]
    fn a_part_is_the_whole_grids_rows() {
        let eval = |cell: Cell, from: Option<(usize, &usize)>| Evaluated {
            point: (cell, from.map(|(j, c)| (j, *c))),
            carry: Some(cell.col * 7 + cell.row),
        };
        let cols = 2 * COARSE_STRIDE + 3;
        for rows in [1, 4] {
            let whole = run_rows(rows, cols, eval);
            for part in [0..rows, rows - 1..rows, 0..0] {
                assert_eq!(
                    run_rows_measured(part.clone(), rows, cols, eval).rows,
                    whole[part].to_vec()
                );
            }
        }
    }

    /// A split row computed as its coarse pass and its fills apart is the row.
    #[test]
    fn coarse_pass_and_fills_make_the_split_row() {
        let eval = |cell: Cell, from: Option<(usize, &usize)>| Evaluated {
            point: (cell, from.map(|(j, c)| (j, *c))),
            carry: (cell.col != 13).then_some(cell.col * 3),
        };
        for cols in [1, COARSE_STRIDE, 2 * COARSE_STRIDE + 3] {
            let whole = run_rows(1, cols, eval).remove(0);
            let (coarse, carries) = coarse_pass(0, cols, &eval);
            let mut parts = Vec::new();
            for (k, (point, left)) in coarse.into_iter().zip(&carries).enumerate() {
                parts.push(point);
                parts.extend(fill(0, cols, k, left.as_ref(), &eval));
            }
            assert_eq!(parts, whole, "{cols} points");
        }
    }

    /// The task graph follows the schedule: rows in order are chains, a split row is its coarse chain with
    /// each fill after its coarse point, independent points are independent; work and span are counted in the
    /// steps each task walks (here `col + 1`), the same for any number of threads.
    #[test]
    fn task_graphs_follow_the_schedule() {
        let eval = |cell: Cell, _: Option<(usize, &())>| {
            (0..=cell.col).for_each(|_| crate::meter::count_step());
            Evaluated {
                point: cell.col,
                carry: Some(()),
            }
        };
        let cols = 2 * COARSE_STRIDE + 3;
        let row = (1..=cols as u64).sum::<u64>();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (rows, split, independent) = pool.install(|| {
                (
                    run_rows_measured(0..3, 3, cols, eval).graph.work_span(),
                    run_rows_measured(0..1, 1, cols, eval).graph.work_span(),
                    run_independent(0..2, cols, |cell| eval(cell, None).point)
                        .graph
                        .work_span(),
                )
            });
            assert_eq!(
                (rows.tasks, rows.work_steps, rows.span_steps),
                (3 * cols, 3 * row, row)
            );
            // The fill of the second interval, after the first two coarse points: 1 + 11 + (12 + ... + 20).
            let fill = (12..=20).sum::<u64>();
            assert_eq!(
                (split.tasks, split.work_steps, split.span_steps),
                (cols, row, 1 + 11 + fill)
            );
            let cols64 = cols as u64;
            assert_eq!(
                (
                    independent.tasks,
                    independent.work_steps,
                    independent.span_steps
                ),
                (2 * cols, 2 * row, cols64)
            );
        }
    }

    #[test]
    fn running_sum_along_rows() {
        // A running sum along each row: the carry is the sum so far.
        let rows = run_rows(2, 25, |cell, from: Option<(usize, &f64)>| {
            let sum = from.map_or(0.0, |(_, s)| *s) + (cell.row * 100 + cell.col) as f64;
            Evaluated {
                point: (cell, sum),
                carry: Some(sum),
            }
        });
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1][24], (Cell { row: 1, col: 24 }, 2800.0));
    }
}
