//! Measured parallelism of a grid job: the work and the span of each of its phases (the gaits, the crossings,
//! the continued curves of a map; the walks of an orbit diagram; ...), in two units.
//!
//! - **Steps walked**, each one evaluation of the step map `P` (failed steps included; the walk of an exact
//!   `DP` counts once, its replay not), counted by the task's [`StepMeter`]: deterministic, the same for any
//!   number of threads, written to the job's JSON summary.
//! - **Seconds**, the wall time of each task: they vary from run to run, so they are printed, never written.
//!
//! A phase is a graph of tasks ([`TaskGraph`]): a task runs after the tasks it continues from or needs, as the
//! grid runner's schedule orders them (`study/grid.rs`). Its **work** is the sum of its tasks' costs, its
//! **span** the costliest chain of dependent tasks: no schedule on any number of threads finishes the phase in
//! less than its span, and `work / span` is the most threads it can keep busy. A task's own parallel work
//! (the two exact Jacobians of a gait, the refinements inside a line's threshold search) is counted in its
//! work and its span alike, so the span is an upper bound of the phase's true critical path.

use std::time::Instant;

use serde::Serialize;

use crate::meter::StepMeter;

/// What one task cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Cost {
    /// Steps walked (evaluations of the step map).
    pub steps: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Run `f` as one task: its result and what it cost (the steps walked under a fresh [`StepMeter`], and the
/// wall time). Its steps count to the thread's meter too, so that a task measured inside another is part of
/// the other's work (a parallel iterator's closure that measures its tasks is [`carried`] by the caller's
/// meter: [`crate::meter::carried`]).
///
/// [`carried`]: crate::meter::carried
pub(crate) fn measured<R>(f: impl FnOnce() -> R) -> (R, Cost) {
    let outer = crate::meter::current();
    let meter = StepMeter::new();
    let clock = Instant::now();
    let out = meter.run(f);
    let cost = Cost {
        steps: meter.steps(),
        seconds: clock.elapsed().as_secs_f64(),
    };
    if let Some(outer) = outer {
        outer.add(cost.steps);
    }
    (out, cost)
}

/// The tasks of one phase and what each waits for. Nodes are added after the nodes they wait for, so the
/// order of addition is a topological order.
#[derive(Debug, Clone, Default)]
pub struct TaskGraph {
    nodes: Vec<Node>,
}

#[derive(Debug, Clone)]
struct Node {
    cost: Cost,
    after: Vec<usize>,
    /// A task (counted in [`WorkSpan::tasks`]), or a join of other nodes at no cost.
    task: bool,
}

impl TaskGraph {
    /// An empty graph.
    pub fn new() -> TaskGraph {
        TaskGraph::default()
    }

    /// Add a task of `cost` that runs after the nodes `after`; its node.
    pub fn task(&mut self, cost: Cost, after: &[usize]) -> usize {
        self.push(Node {
            cost,
            after: after.to_vec(),
            task: true,
        })
    }

    /// Add a node at no cost that waits for the nodes `after` (the end of a row, say); its node.
    pub fn join(&mut self, after: &[usize]) -> usize {
        self.push(Node {
            cost: Cost::default(),
            after: after.to_vec(),
            task: false,
        })
    }

    /// Add every node of `other` (its nodes without predecessors after `after`); the nodes of `other`'s
    /// indices in this graph start at the returned offset.
    pub fn extend(&mut self, other: TaskGraph, after: &[usize]) -> usize {
        let offset = self.nodes.len();
        for node in other.nodes {
            let after = match node.after.is_empty() {
                true => after.to_vec(),
                false => node.after.iter().map(|&k| k + offset).collect(),
            };
            self.push(Node { after, ..node });
        }
        offset
    }

    fn push(&mut self, node: Node) -> usize {
        debug_assert!(node.after.iter().all(|&k| k < self.nodes.len()));
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// No node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The work and span of the graph, in steps and in seconds (each its own costliest chain).
    pub fn work_span(&self) -> WorkSpan {
        let mut finish: Vec<(u64, f64)> = Vec::with_capacity(self.nodes.len());
        let mut w = WorkSpan::default();
        for node in &self.nodes {
            let start = node.after.iter().fold((0, 0.0), |(s, t), &k| {
                (s.max(finish[k].0), f64::max(t, finish[k].1))
            });
            finish.push((start.0 + node.cost.steps, start.1 + node.cost.seconds));
            w.tasks += usize::from(node.task);
            w.work_steps += node.cost.steps;
            w.work_seconds += node.cost.seconds;
        }
        w.span_steps = finish.iter().map(|f| f.0).max().unwrap_or(0);
        w.span_seconds = finish.iter().map(|f| f.1).fold(0.0, f64::max);
        w
    }
}

/// The work and span of one phase (see the module documentation); the seconds are printed, not written.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct WorkSpan {
    /// Tasks in the phase.
    pub tasks: usize,
    /// Steps walked by all tasks.
    pub work_steps: u64,
    /// Steps walked along the costliest chain of dependent tasks.
    pub span_steps: u64,
    /// Wall-clock seconds of all tasks, summed (printed, not written: files are reproducible).
    #[serde(skip)]
    pub work_seconds: f64,
    /// Wall-clock seconds along the longest chain of dependent tasks (printed, not written).
    #[serde(skip)]
    pub span_seconds: f64,
}

impl WorkSpan {
    /// `work / span` in steps walked: the most threads the phase can keep busy (0 without work).
    pub fn parallelism(&self) -> f64 {
        match self.span_steps {
            0 => 0.0,
            span => self.work_steps as f64 / span as f64,
        }
    }
}

/// One phase of a job and its work and span (an entry of a JSON summary's `parallelism`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhaseWork {
    /// The phase (`gaits`, `crossings`, `continued_curves`, `walks`, ...).
    pub phase: &'static str,
    /// Its work and span.
    #[serde(flatten)]
    pub work: WorkSpan,
}

impl PhaseWork {
    /// The phase `phase` of `graph`.
    pub fn of(phase: &'static str, graph: &TaskGraph) -> PhaseWork {
        PhaseWork {
            phase,
            work: graph.work_span(),
        }
    }
}

/// A job's JSON summary with its phases' work and span (`parallelism`, after the summary's own fields): what
/// the job writes to its file. The summary alone is what the library returns (and the Python front hands on).
#[derive(Debug, Serialize)]
pub struct WithParallelism<'a, T> {
    /// The summary's fields.
    #[serde(flatten)]
    pub summary: &'a T,
    /// Each phase's work and span, in steps walked.
    pub parallelism: &'a [PhaseWork],
}

impl std::fmt::Display for PhaseWork {
    /// The phase for the terminal: its tasks, its work and span in steps and their ratio, the same in seconds
    /// (`gaits: 441 tasks, work / span 15392 / 1310 steps = 11.7 (17.10 s / 1.31 s = 13.1)`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let w = &self.work;
        let seconds = match w.span_seconds > 0.0 {
            true => w.work_seconds / w.span_seconds,
            false => 0.0,
        };
        write!(
            f,
            "{}: {} tasks, work / span {} / {} steps = {:.1} ({:.2} s / {:.2} s = {:.1})",
            self.phase,
            w.tasks,
            w.work_steps,
            w.span_steps,
            w.parallelism(),
            w.work_seconds,
            w.span_seconds,
            seconds
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(steps: u64) -> Cost {
        Cost {
            steps,
            seconds: steps as f64 / 10.0,
        }
    }

    /// Two chains joined: the work is the sum, the span the costlier chain plus what follows the join; a
    /// graph appended after a node starts where that node ends.
    #[test]
    fn span_is_the_costliest_chain() {
        let mut g = TaskGraph::new();
        let a = g.task(cost(3), &[]);
        let b = g.task(cost(4), &[a]);
        let c = g.task(cost(10), &[]);
        let end = g.join(&[b, c]);
        g.task(cost(1), &[end]);
        let w = g.work_span();
        assert_eq!((w.tasks, w.work_steps, w.span_steps), (4, 18, 11));
        assert!((w.work_seconds - 1.8).abs() < 1e-12 && (w.span_seconds - 1.1).abs() < 1e-12);
        let mut other = TaskGraph::new();
        let x = other.task(cost(5), &[]);
        other.task(cost(5), &[x]);
        other.task(cost(2), &[]);
        g.extend(other, &[b]);
        let w = g.work_span();
        assert_eq!((w.tasks, w.work_steps, w.span_steps), (7, 30, 17));
        assert_eq!(TaskGraph::new().work_span(), WorkSpan::default());
        assert_eq!(WorkSpan::default().parallelism(), 0.0);
    }
}
