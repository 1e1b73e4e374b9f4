//! Text-level work on TOML scene files: edits of byte ranges that keep track of where the
//! original text was, and floats written so that people can read them.

use std::ops::Range;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Replacements of byte ranges of the original text, in no particular order.
#[derive(Default)]
pub(super) struct Edits(Vec<(Range<usize>, String)>);

impl Edits {
    /// The text with the edits applied, and the edits sorted for [`Edits::original_offset`].
    pub(super) fn apply(&mut self, s: &str) -> String {
        self.0.sort_by_key(|(r, _)| r.start);
        let mut out = String::with_capacity(s.len());
        let mut at = 0;
        for (r, text) in &self.0 {
            out.push_str(s.get(at..r.start).unwrap_or(""));
            out.push_str(text);
            at = r.end;
        }
        out.push_str(s.get(at..).unwrap_or(""));
        out
    }

    /// The offset in the original text of offset `p` in the edited text (the start of an
    /// edit for an offset inside it).
    pub(super) fn original_offset(&self, p: usize) -> usize {
        let mut shift = 0_isize; // edited − original, before the current edit
        for (r, text) in &self.0 {
            let start = (r.start as isize + shift) as usize;
            if p < start {
                break;
            }
            if p < start + text.len() {
                return r.start;
            }
            shift += text.len() as isize - r.len() as isize;
        }
        (p as isize - shift).max(0) as usize
    }

    pub(super) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

pub(super) fn number(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Float(x) => match x.as_str() {
            "nan" | "+nan" | "-nan" => Some(f64::NAN),
            t => t.replace('_', "").parse().ok(),
        },
        DeValue::Integer(i) => i64::from_str_radix(&i.as_str().replace('_', ""), i.radix())
            .ok()
            .map(|i| i as f64),
        _ => None,
    }
}

/// `x` as a TOML float that reads back exactly.
pub(super) fn float_text(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:?}")
    }
}

impl Edits {
    /// Adds the replacement of `range` by `text`.
    pub(super) fn push(&mut self, range: Range<usize>, text: String) {
        self.0.push((range, text));
    }
}

/// `text` (TOML as the serialiser writes it) with every float in the shortest form that reads
/// back exactly, in exponent notation where that is shorter: `1e-76` rather than 76 zeros.
pub(super) fn tidy_floats(text: &str) -> String {
    let Ok(doc) = DeTable::parse(text) else {
        return text.to_string();
    };
    let mut edits = Edits::default();
    fn walk(v: &Spanned<DeValue<'_>>, edits: &mut Edits) {
        match v.get_ref() {
            DeValue::Float(_) => {
                if let Some(x) = number(v.get_ref()) {
                    edits.push(v.span(), float_text(x));
                }
            }
            DeValue::Array(items) => items.iter().for_each(|i| walk(i, edits)),
            DeValue::Table(t) => t.values().for_each(|i| walk(i, edits)),
            _ => {}
        }
    }
    doc.get_ref().values().for_each(|v| walk(v, &mut edits));
    edits.apply(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_are_short_and_exact() {
        let text = "a = 0.0000000000000000000000000000000000000000000000000000000000000000000000000001\nb = [0.06, 300000.0]\n[c]\nd = { e = 0.00000001, f = 1 }\n";
        let tidy = tidy_floats(text);
        assert_eq!(
            tidy,
            "a = 1e-76\nb = [0.06, 300000.0]\n[c]\nd = { e = 1e-8, f = 1 }\n"
        );
    }

    #[test]
    fn edits_map_offsets_back() {
        let mut e = Edits::default();
        e.push(4..6, "xyz".into()); // "ab = 12\n" → "ab = xyz\n"... offsets of the original
        let s = "ab =12 cd";
        assert_eq!(e.apply(s), "ab =xyz cd");
        assert_eq!(e.original_offset(2), 2);
        assert_eq!(e.original_offset(5), 4); // inside the edit: its start
        assert_eq!(e.original_offset(8), 7); // after it: shifted back by the growth
    }
}
