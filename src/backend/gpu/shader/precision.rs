//! The arithmetic width a pass is compiled for.
//!
//! WGSL has no type parameters and an `override` cannot name a type, so the one source of every
//! shader is written in f64 (the exact mode, twin of the CPU reference) and the mixed mode's
//! f32 text is derived from it token by token: the type `f64` becomes `f32` and an f64 literal
//! (`1.5lf`) an f32 one (`1.5f`). Lines and columns stay where they were, so naga's errors
//! still point at the file a person edits. A literal beyond f32's range (the "larger than any
//! coordinate" sentinels) becomes f32's largest finite value, which keeps its meaning.
//!
//! Which quantities can live in f32 and which need more is decided from measurement in
//! `DESIGN.md` ("Precision"); the contact law, written in ratios (x = a/a₀, d = δ/δ₀) and
//! relative vectors, is the part this derivation serves as it stands.

/// Arithmetic width of a compiled pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f64 throughout (needs `SHADER_F64`): the CPU reference's bits.
    Exact,
    /// f32 arithmetic; runs on adapters without `SHADER_F64` (Metal, most integrated GPUs,
    /// browsers).
    Mixed,
}

impl Precision {
    /// Both, in the order the tests and benches report them.
    pub const ALL: [Precision; 2] = [Precision::Exact, Precision::Mixed];

    /// The name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Precision::Exact => "exact",
            Precision::Mixed => "mixed",
        }
    }

    /// naga capabilities a pass compiled for this precision may use: the mixed text must
    /// validate without `FLOAT64`, so a stray f64 in it is an error, not a slow path.
    pub fn capabilities(self) -> naga::valid::Capabilities {
        match self {
            Precision::Exact => naga::valid::Capabilities::FLOAT64,
            Precision::Mixed => naga::valid::Capabilities::empty(),
        }
    }

    /// The text of `source` at this precision (`source` is the f64 text).
    pub fn apply(self, source: &str) -> String {
        match self {
            Precision::Exact => source.to_string(),
            Precision::Mixed => to_f32_text(source),
        }
    }
}

/// f32's largest finite value as a WGSL literal (f32::MAX, correctly rounded).
const F32_MAX_LITERAL: &str = "3.4028235e38f";

/// Rewrites the f64 type and f64 literals of WGSL `text` to f32, leaving comments and every
/// other token as they are.
fn to_f32_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        let (code, comment) = match line.find("//") {
            Some(at) => line.split_at(at),
            None => (line, ""),
        };
        rewrite_code(code, &mut out);
        out.push_str(comment);
    }
    out
}

/// One line's code (no comment): identifiers and numbers are whole tokens.
fn rewrite_code(code: &str, out: &mut String) {
    let bytes = code.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_alphabetic() || c == b'_' {
            let end = scan(bytes, i, |b, _| b.is_ascii_alphanumeric() || b == b'_');
            let word = &code[i..end];
            out.push_str(if word == "f64" { "f32" } else { word });
            i = end;
        } else if c.is_ascii_digit()
            || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let end = scan(bytes, i, number_continues);
            out.push_str(&f32_literal(&code[i..end]));
            i = end;
        } else {
            let ch = code[i..].chars().next().expect("inside the line");
            out.push(ch);
            i += ch.len_utf8();
        }
    }
}

/// End of the token starting at `start` whose bytes satisfy `more(byte, previous)`.
fn scan(bytes: &[u8], start: usize, more: impl Fn(u8, u8) -> bool) -> usize {
    let mut end = start + 1;
    while end < bytes.len() && more(bytes[end], bytes[end - 1]) {
        end += 1;
    }
    end
}

/// Digits, letters (suffixes, exponent, hex), the point, and a sign right after an exponent.
fn number_continues(b: u8, previous: u8) -> bool {
    b.is_ascii_alphanumeric()
        || b == b'.'
        || b == b'_'
        || ((b == b'-' || b == b'+') && (previous == b'e' || previous == b'E'))
}

/// An f64 literal (`…lf`) as f32; any other number unchanged.
fn f32_literal(number: &str) -> String {
    let Some(digits) = number.strip_suffix("lf") else {
        return number.to_string();
    };
    match digits.parse::<f64>() {
        Ok(v) if v.abs() > f32::MAX as f64 => F32_MAX_LITERAL.to_string(),
        _ => format!("{digits}f"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_f32_text_changes_types_and_f64_literals_only() {
        let f64_text = "const A: f64 = 1e-15lf; // f64 stays in 1.0lf comments\n\
                        fn g(v: vec3<f64>) -> f64 { return f64(2u) * 0.5lf + 1.2e3lf + 7u; }\n\
                        let f64x = 3; let big = -1.7976931348623157e308lf; let h = 0x1fu;\n";
        let expected = "const A: f32 = 1e-15f; // f64 stays in 1.0lf comments\n\
                        fn g(v: vec3<f32>) -> f32 { return f32(2u) * 0.5f + 1.2e3f + 7u; }\n\
                        let f64x = 3; let big = -3.4028235e38f; let h = 0x1fu;\n";
        assert_eq!(Precision::Mixed.apply(f64_text), expected);
        assert_eq!(Precision::Exact.apply(f64_text), f64_text);
    }

    #[test]
    fn the_largest_f32_literal_is_f32_max() {
        let v: f32 = F32_MAX_LITERAL.trim_end_matches('f').parse().unwrap();
        assert_eq!(v, f32::MAX);
    }

    #[test]
    fn precision_names_are_the_command_line_words() {
        let names: Vec<_> = Precision::ALL.iter().map(|p| p.name()).collect();
        assert_eq!(names, ["exact", "mixed"]);
        assert!(Precision::Mixed.capabilities().is_empty());
        assert!(Precision::Exact
            .capabilities()
            .contains(naga::valid::Capabilities::FLOAT64));
    }
}
