//! Where a remesh's wall-clock time went, phase by phase: measured through the progress
//! callback of [`remesh_guided`](super::super::remesh_guided), so the remesher itself keeps no
//! clock and its output stays a function of its input.

use super::super::RemeshPhase;
use std::cell::RefCell;
use std::time::Instant;

/// Wall-clock seconds of each phase of one remesh.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseSeconds {
    /// Before classification: whether the input is kept as it is
    /// ([`RemeshPhase::KeepInput`]), the plate and flatness probes and the lattice's set-up.
    pub probes: f64,
    /// [`RemeshPhase::Classify`].
    pub classify: f64,
    /// [`RemeshPhase::Extract`].
    pub extract: f64,
    /// [`RemeshPhase::Place`].
    pub place: f64,
    /// [`RemeshPhase::Simplify`] (0 without simplification).
    pub simplify: f64,
}

impl PhaseSeconds {
    /// The phases with their names, in the order they run.
    pub fn named(&self) -> [(&'static str, f64); 5] {
        [
            ("probes", self.probes),
            ("classify", self.classify),
            ("extract", self.extract),
            ("place", self.place),
            ("simplify", self.simplify),
        ]
    }

    /// As a JSON object (`{"probes": 0.012, ...}`, milliseconds' precision).
    pub fn to_json(&self) -> String {
        let members: Vec<String> = self
            .named()
            .iter()
            .map(|(name, s)| format!("\"{name}\": {s:.3}"))
            .collect();
        format!("{{{}}}", members.join(", "))
    }
}

/// Notes when each phase begins; hand [`PhaseClock::mark`] to the progress callback (next to
/// any other use of it) and read [`PhaseClock::seconds`] when the remesh returns.
///
/// ```
/// use gwn::eval::antipodal::WindingNumber;
/// use gwn::products::remesh::report::PhaseClock;
/// use gwn::products::remesh::{RemeshOptions, remesh_guided};
/// let tet = gwn::Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
/// )?;
/// let wn = WindingNumber::new(&tet)?;
/// let clock = PhaseClock::start();
/// let bounds = tet.bounding_box().unwrap();
/// let options = RemeshOptions::with_resolution(16);
/// remesh_guided(&wn, None, bounds, &options, &|phase| clock.mark(phase))?;
/// let seconds = clock.seconds();
/// assert!(seconds.classify > 0.0 && seconds.simplify > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct PhaseClock {
    start: Instant,
    marks: RefCell<Vec<(RemeshPhase, Instant)>>,
}

impl PhaseClock {
    /// A clock started now (call it just before the remesh).
    pub fn start() -> PhaseClock {
        PhaseClock {
            start: Instant::now(),
            marks: RefCell::new(Vec::with_capacity(4)),
        }
    }

    /// `phase` begins now.
    pub fn mark(&self, phase: RemeshPhase) {
        self.marks.borrow_mut().push((phase, Instant::now()));
    }

    /// Each phase's seconds, the last one ending now (call it as the remesh returns). A phase
    /// that did not run (simplification turned off, a run stopped early) counts 0.
    pub fn seconds(&self) -> PhaseSeconds {
        let now = Instant::now();
        let marks = self.marks.borrow();
        let mut out = PhaseSeconds {
            probes: marks
                .first()
                .map_or(now, |&(_, at)| at)
                .duration_since(self.start)
                .as_secs_f64(),
            ..PhaseSeconds::default()
        };
        for (i, &(phase, begin)) in marks.iter().enumerate() {
            let end = marks.get(i + 1).map_or(now, |&(_, at)| at);
            let seconds = end.duration_since(begin).as_secs_f64();
            *match phase {
                RemeshPhase::KeepInput => &mut out.probes,
                RemeshPhase::Classify => &mut out.classify,
                RemeshPhase::Extract => &mut out.extract,
                RemeshPhase::Place => &mut out.place,
                RemeshPhase::Simplify => &mut out.simplify,
            } += seconds;
        }
        out
    }
}
