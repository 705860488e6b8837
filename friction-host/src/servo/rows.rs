//! The benchmark's rows: every compensation, named once ([`ROWS`]).

/// Which adaptive law a row runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// Per-parameter adaptation ([`friction_core::ParameterAdaptive`]): the
    /// Coulomb level per direction, the Stribeck excess, the viscous and the
    /// load coefficient, each in its own box.
    Parameters,
    /// The θ law ([`friction_core::AdaptiveObserver`]): one factor on the
    /// whole model.
    Theta,
}

/// What a row compensates with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Row {
    /// The plant without friction, no compensation.
    NoFriction,
    /// No compensation.
    None,
    /// Coulomb + viscous feed-forward from the nominal parameters times `scale`.
    Static {
        /// Factor on the Coulomb level.
        scale: f64,
    },
    /// The model's observer, friction level times `scale`, stiffness times `stiffness`.
    Observer {
        /// Factor on `fc`, `fs`.
        scale: f64,
        /// Factor on the stiffness (`sigma0` and its kin).
        stiffness: f64,
        /// Whether `sigma1 dz^/dt` is included.
        damping: bool,
    },
    /// An adaptive observer around the model times `scale`, `stiffness`,
    /// supervised (unless the file turns the supervisor off) with the
    /// static feed-forward of the same scale as its fallback.
    Adaptive {
        /// Factor on `fc`, `fs`.
        scale: f64,
        /// Factor on the stiffness.
        stiffness: f64,
        /// The adaptive law.
        law: Law,
    },
    /// The least-squares Coulomb + viscous feed-forward.
    Rls,
}

/// Every compensation, in order: its name and its row. [`NAMES`] and
/// [`Row::named`] read this one table.
pub const ROWS: [(&str, Row); 16] = [
    ("nofriction", Row::NoFriction),
    ("none", Row::None),
    ("static", Row::Static { scale: 1.0 }),
    ("static+50", Row::Static { scale: 1.5 }),
    ("static-50", Row::Static { scale: 0.5 }),
    ("observer", Row::observer(1.0, true)),
    ("observer+50", Row::observer(1.5, true)),
    ("observer-50", Row::observer(0.5, true)),
    ("observer-nodamping", Row::observer(1.0, false)),
    ("adaptive", Row::adaptive(1.0, Law::Parameters)),
    ("adaptive+50", Row::adaptive(1.5, Law::Parameters)),
    ("adaptive-50", Row::adaptive(0.5, Law::Parameters)),
    ("adaptive-theta", Row::adaptive(1.0, Law::Theta)),
    ("adaptive-theta+50", Row::adaptive(1.5, Law::Theta)),
    ("adaptive-theta-50", Row::adaptive(0.5, Law::Theta)),
    ("rls", Row::Rls),
];

/// Every compensation's name, in order (the names of [`ROWS`]).
pub const NAMES: [&str; ROWS.len()] = {
    let mut names = [""; ROWS.len()];
    let mut i = 0;
    while i < ROWS.len() {
        names[i] = ROWS[i].0;
        i += 1;
    }
    names
};

impl Row {
    /// The row called `name` of [`ROWS`].
    pub fn named(name: &str) -> Option<Row> {
        ROWS.iter().find(|(n, _)| *n == name).map(|&(_, row)| row)
    }

    /// The observer at friction level `scale`, nominal stiffness.
    const fn observer(scale: f64, damping: bool) -> Row {
        Row::Observer {
            scale,
            stiffness: 1.0,
            damping,
        }
    }

    /// The adaptive observer of `law` around the model times `scale`,
    /// nominal stiffness.
    const fn adaptive(scale: f64, law: Law) -> Row {
        Row::Adaptive {
            scale,
            stiffness: 1.0,
            law,
        }
    }

    /// This row with its friction level times `by` and its stiffness times
    /// `stiffer` (rows without them unchanged): a cell of the robustness
    /// map.
    pub fn scaled(self, by: f64, stiffer: f64) -> Row {
        match self {
            Row::Static { scale } => Row::Static { scale: scale * by },
            Row::Observer {
                scale,
                stiffness,
                damping,
            } => Row::Observer {
                scale: scale * by,
                stiffness: stiffness * stiffer,
                damping,
            },
            Row::Adaptive {
                scale,
                stiffness,
                law,
            } => Row::Adaptive {
                scale: scale * by,
                stiffness: stiffness * stiffer,
                law,
            },
            row => row,
        }
    }

    pub(super) fn scale(&self) -> f64 {
        match *self {
            Row::Static { scale } | Row::Observer { scale, .. } | Row::Adaptive { scale, .. } => {
                scale
            }
            _ => 1.0,
        }
    }
}
