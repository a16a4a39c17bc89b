//! The generators as proptest strategies (feature `testing`).
//!
//! Each strategy draws a byte vector and decodes it with [`Kind::from_bytes`], so proptest
//! shrinks the bytes (towards zeros: fewer, simpler choices) and a failing case can be replayed
//! with the same decoder from a fuzz corpus.
//!
//! ```
//! use gwn::testing::{strategies, Oracle};
//! use gwn::RayAxis;
//! use proptest::prelude::*;
//! proptest!(ProptestConfig::with_cases(8), |(case in strategies::polycube())| {
//!     let oracle = Oracle::new(&case.mesh, RayAxis::PosZ);
//!     for &q in &case.queries {
//!         // Closed polycubes: the oracle's answer is an exact integer.
//!         prop_assert!(oracle.eval(q).is_exact());
//!     }
//! });
//! ```

use proptest::prelude::*;

use super::generators::{Case, Kind};

/// Length range of the byte vectors for `kind` (long enough for every choice it makes).
pub fn byte_len(kind: Kind) -> std::ops::Range<usize> {
    match kind {
        Kind::Soup => 0..96,
        Kind::Boxes => 8..128,
        Kind::Polycube | Kind::TJunction | Kind::Open | Kind::Inconsistent => 64..640,
        Kind::Fan | Kind::Tets => 16..192,
    }
}

/// Byte vectors for `kind`'s decoder.
pub fn bytes(kind: Kind) -> impl Strategy<Value = Vec<u8>> {
    proptest::collection::vec(any::<u8>(), byte_len(kind))
}

/// Cases of `kind`.
pub fn case(kind: Kind) -> impl Strategy<Value = Case> {
    bytes(kind).prop_map(move |b| kind.from_bytes(&b))
}

/// Cases of any kind.
pub fn any_case() -> impl Strategy<Value = Case> {
    (
        0..Kind::ALL.len(),
        proptest::collection::vec(any::<u8>(), 0..640),
    )
        .prop_map(|(k, b)| Kind::ALL[k].from_bytes(&b))
}

macro_rules! strategies {
    ($($kind:ident, $name:ident;)*) => {$(
        #[doc = concat!("[`Kind::", stringify!($kind), "`] cases (see its guarantee).")]
        pub fn $name() -> impl Strategy<Value = Case> {
            case(Kind::$kind)
        }
    )*};
}

strategies! {
    Soup, soup;
    Boxes, boxes;
    Polycube, polycube;
    TJunction, t_junction;
    Open, open;
    Inconsistent, inconsistent;
    Fan, fan;
    Tets, tets;
}
