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

#[cfg(test)]
mod tests {
    use super::short;

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
