//! The CPU engine's bottom layer: four f64 lanes and the choice of instructions that runs
//! them.
//!
//! [`ContactLanes`] is what the passes are told: one contact at a time, or four at a time in
//! portable code or in AVX2. `four.rs` holds the lanes themselves ([`F4`], [`V4`], [`M4`]) and
//! the instruction sets ([`Isa`]: [`Portable`], `Avx2`), private to the crate: `Avx2`'s safe
//! methods issue AVX instructions, and public code reaches them only through an entry point
//! that takes a [`ContactLanes`] and goes through [`in_lanes!`], the one place that checks the
//! processor and enters AVX2 code.

mod four;

#[cfg(target_arch = "x86_64")]
pub(crate) use four::Avx2;
pub(crate) use four::{Isa, Portable, F4, M4, V4};
use std::sync::OnceLock;

/// How the force pass evaluates the contact law: one contact at a time, or four at a time in
/// the target's baseline vector instructions (SSE2 on x86-64: two lanes per register) or in
/// AVX2 (four per register), chosen at run time. All give the same bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactLanes {
    Scalar,
    Portable,
    Avx2,
}

/// The environment variable that picks [`ContactLanes`] (`scalar`, `portable`, `avx2`), to
/// measure one against another; unset, the best the processor has.
pub const CONTACT_LANES_VAR: &str = "DUSTDEM_CONTACT_LANES";

impl ContactLanes {
    /// The best this processor runs.
    pub fn detected() -> ContactLanes {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            return ContactLanes::Avx2;
        }
        ContactLanes::Portable
    }

    /// [`CONTACT_LANES_VAR`] if set (an error names the value and the choices, or says the
    /// processor lacks it), else [`ContactLanes::detected`].
    pub fn from_env() -> Result<ContactLanes, String> {
        let Ok(value) = std::env::var(CONTACT_LANES_VAR) else {
            return Ok(ContactLanes::detected());
        };
        let lanes = match value.as_str() {
            "scalar" => ContactLanes::Scalar,
            "portable" => ContactLanes::Portable,
            "avx2" => ContactLanes::Avx2,
            _ => {
                return Err(format!(
                    "{CONTACT_LANES_VAR}={value:?}: allowed are scalar, portable and avx2"
                ))
            }
        };
        if lanes == ContactLanes::Avx2 && ContactLanes::detected() != ContactLanes::Avx2 {
            return Err(format!(
                "{CONTACT_LANES_VAR}=avx2: this processor has no AVX2 (allowed: scalar, portable)"
            ));
        }
        Ok(lanes)
    }

    /// What the engine runs: [`ContactLanes::from_env`], read once; an unusable setting falls
    /// back to the detected lanes (the command line refuses it before any engine starts).
    pub fn chosen() -> ContactLanes {
        static CHOSEN: OnceLock<ContactLanes> = OnceLock::new();
        *CHOSEN.get_or_init(|| ContactLanes::from_env().unwrap_or_else(|_| Self::detected()))
    }

    /// For reports: which instructions evaluate the contacts.
    pub fn describe(self) -> &'static str {
        match self {
            ContactLanes::Scalar => "scalar f64, one contact at a time",
            ContactLanes::Portable => "4 contacts at a time, baseline vector instructions",
            ContactLanes::Avx2 => "4 contacts at a time, AVX2 (4 f64 lanes per register)",
        }
    }
}

/// Runs `f::<S>(values)` with `S` the instruction set `lanes` names: for
/// [`ContactLanes::Avx2`], in a `#[target_feature(enable = "avx2")]` function, after asserting
/// that the processor has AVX2 ([`ContactLanes::from_env`] never picks it where not); the
/// portable lanes otherwise, and for [`ContactLanes::Scalar`] the `scalar` expression where
/// one is given. The parameters after `as` are the AVX2 function's: the arguments' names and
/// types.
///
/// ```ignore
/// in_lanes!(lanes, chunk_in_lanes(law, m, chunk) as (law: &ContactLaw, m: &Monomers, chunk: ForceChunk),
///     scalar => chunk_scalar(law, m, chunk))
/// ```
///
/// Each use expands to the match and the AVX2 function each pass used to write out: the same
/// code, one definition.
macro_rules! in_lanes {
    (
        $lanes:expr,
        $f:ident($($value:expr),* $(,)?) as ($($arg:ident: $ty:ty),* $(,)?)
        $(, scalar => $scalar:expr)? $(,)?
    ) => {
        match $lanes {
            $($crate::backend::cpu::lanes::ContactLanes::Scalar => $scalar,)?
            #[cfg(target_arch = "x86_64")]
            $crate::backend::cpu::lanes::ContactLanes::Avx2 => {
                /// The lanes in AVX2.
                ///
                /// # Safety
                ///
                /// The processor must have AVX2.
                #[target_feature(enable = "avx2")]
                unsafe fn avx2($($arg: $ty),*) {
                    $f::<$crate::backend::cpu::lanes::Avx2>($($arg),*)
                }
                assert!(std::arch::is_x86_feature_detected!("avx2"));
                // SAFETY: the processor has AVX2 (checked above).
                unsafe { avx2($($value),*) }
            }
            _ => $f::<$crate::backend::cpu::lanes::Portable>($($value),*),
        }
    };
}

pub(crate) use in_lanes;
