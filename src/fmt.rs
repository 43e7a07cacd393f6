//! Numbers written for people: the short form used in messages, titles and summaries.

/// A number in short form for messages: up to 6 significant digits, scientific notation when very small or
/// very large.
pub fn short(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-3..1e6).contains(&a) {
        let text = format!("{v:.6}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        let text = format!("{v:.5e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) if mantissa.contains('.') => format!(
                "{}e{exponent}",
                mantissa.trim_end_matches('0').trim_end_matches('.')
            ),
            _ => text,
        }
    }
}

/// Serialize a value as its text ([`std::fmt::Display`]): a status is an enum inside the library and its
/// name in a file (`#[serde(serialize_with = "crate::fmt::as_text")]`).
pub fn as_text<T: std::fmt::Display, S: serde::Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_str(value)
}

/// The most characters of a user's input a message quotes ([`clip`]).
pub const QUOTED_INPUT_CHARS: usize = 200;

/// A user's input as a message quotes it: whole up to [`QUOTED_INPUT_CHARS`] characters, else its first
/// [`QUOTED_INPUT_CHARS`] and how long it is (a value of a megabyte must not become a message of a megabyte).
pub fn clip(input: &str) -> String {
    let total = input.chars().count();
    if total <= QUOTED_INPUT_CHARS {
        return input.to_string();
    }
    let head: String = input.chars().take(QUOTED_INPUT_CHARS).collect();
    format!("{head}… ({total} characters in all)")
}

/// Every line of `text` (e.g. a parser's message, which quotes the input's line) [`clip`]ped.
pub fn clip_lines(text: &str) -> String {
    text.lines().map(clip).collect::<Vec<_>>().join("\n")
}

/// The first `most` of `items`, comma-separated, and how many more there are (`a, b, c and 4 more{what}`, with
/// `what` e.g. ` files`): a list in a message that stays short however long the list.
pub fn first_of(items: &[String], most: usize, what: &str) -> String {
    let mut words = items
        .iter()
        .take(most)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > most {
        words += &format!(" and {} more{what}", items.len() - most);
    }
    words
}

#[cfg(test)]
mod tests {
    use super::{clip, short};

    #[test]
    fn long_input_is_clipped_short_input_kept() {
        assert_eq!(clip("viscosity=50"), "viscosity=50");
        let long = "é".repeat(1000);
        let clipped = clip(&long);
        assert!(clipped.starts_with(&"é".repeat(200)), "{clipped}");
        assert!(clipped.ends_with("… (1000 characters in all)"), "{clipped}");
        assert_eq!(
            clipped.chars().count(),
            200 + "… (1000 characters in all)".chars().count()
        );
    }

    #[test]
    fn short_numbers() {
        for (v, text) in [
            (0.0, "0"),
            (1.0, "1"),
            (-10.0, "-10"),
            (0.1, "0.1"),
            (123.456789, "123.456789"),
            (1e308, "1e308"),
            (1e-300, "1e-300"),
            (-2.5e-7, "-2.5e-7"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(short(v), text, "{v:e}");
        }
    }
}
