//! A fuzz test of the configuration reader (proptest): generated TOML documents and `--set` strings, with
//! keys from the real key list and junk keys, values of every type (huge, tiny, NaN, infinite, negative,
//! strings, arrays, tables) and random whitespace and quoting. Every case must end (no panic, no hang: each
//! runs on its own thread with a deadline), and every error must name a key the input gave or the malformed
//! fragment.

use std::sync::mpsc;
use std::time::Duration;

use proptest::prelude::*;
use proptest::test_runner::{Config as RunnerConfig, TestCaseError};
use vrw::params::{Config, ConfigError};

/// How long one case may take before it counts as a hang.
const CASE_DEADLINE: Duration = Duration::from_secs(10);

/// Cases per property: a few thousand in all within a few seconds.
const CASES: u32 = 1500;

/// Every key of a configuration, as a TOML file holds them.
fn real_keys() -> Vec<String> {
    toml::Table::try_from(Config::default())
        .expect("the defaults serialize")
        .keys()
        .cloned()
        .collect()
}

/// A key: a real one most of the time, otherwise junk (misspelt, empty, dotted, spaced, non-ASCII).
fn key() -> impl Strategy<Value = String> {
    let junk = prop_oneof![
        Just("viscosityy".to_string()),
        Just("Viscosity".to_string()),
        Just("legs2".to_string()),
        Just("a-b".to_string()),
        Just("ü".to_string()),
        "[a-z_]{1,12}",
    ];
    prop_oneof![
        4 => proptest::sample::select(real_keys()),
        1 => junk,
    ]
}

/// A value as TOML text: numbers of every size and sign, the non-finite spellings, booleans, strings,
/// arrays, inline tables and text that is not TOML at all.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<i64>().prop_map(|n| n.to_string()),
        any::<f64>().prop_map(|x| format!("{x:e}")),
        (-400i32..400).prop_map(|e| format!("1e{e}")),
        (-400i32..400).prop_map(|e| format!("-2.5e{e}")),
        proptest::sample::select(vec![
            "nan",
            "inf",
            "-inf",
            "+inf",
            "0",
            "-0.0",
            "1_000",
            "0x10",
            "8.0",
            "3",
            "1e9",
            "1e-400",
            "1e400",
            "99999999999999999999999",
            "true",
            "false",
            "\"dlsi\"",
            "\"traditional\"",
            "\"slide\"",
            "\"rebound\"",
            "\"dop853\"",
            "\"dopri5\"",
            "[1, 2]",
            "[]",
            "{ a = 1 }",
            "{}",
            "\"\"",
            "'50'",
            "\"50\"",
            "= 3",
            "5 5",
            "\"unterminated",
        ])
        .prop_map(str::to_string),
        "[a-z0-9 .+-]{0,10}".prop_map(|s| format!("\"{s}\"")),
        "[a-z0-9.+-]{1,10}",
    ]
}

/// A key as written in a document: bare, or quoted.
fn written_key(key: &str, quoted: bool) -> String {
    if quoted || key.is_empty() || !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        format!("{key:?}")
    } else {
        key.to_string()
    }
}

/// One line of a document: `key = value` with random spacing and quoting, or a stray line.
fn line() -> impl Strategy<Value = (Option<String>, String)> {
    let assignment = (key(), value(), any::<bool>(), "[ \t]{0,3}", "[ \t]{0,3}").prop_map(
        |(key, value, quoted, before, after)| {
            let text = format!("{}{before}={after}{value}", written_key(&key, quoted));
            (Some(key), text)
        },
    );
    // A stray line, with the key it defines if any (a table header defines one).
    let stray = proptest::sample::select(vec![
        (None, ""),
        (None, "# a comment"),
        (Some("table"), "[table]"),
        (Some("array"), "[[array]]"),
        (None, "==="),
        (None, "viscosity"),
        (None, "  "),
        (Some("x"), "x.y = 1"),
    ])
    .prop_map(|(key, s)| (key.map(str::to_string), s.to_string()));
    prop_oneof![6 => assignment, 1 => stray]
}

/// Runs `f` on its own thread and waits at most [`CASE_DEADLINE`] for it.
fn bounded<T: Send + 'static>(
    what: String,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, TestCaseError> {
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(f());
    });
    match receive.recv_timeout(CASE_DEADLINE) {
        Ok(value) => Ok(value),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(TestCaseError::fail(format!(
            "{what}: no answer within {CASE_DEADLINE:?}"
        ))),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            Err(TestCaseError::fail(format!("{what}: panicked")))
        }
    }
}

/// Every problem of `error` names one of `keys` (a key error), or is a syntax error with its position, or
/// quotes one of `fragments` (a malformed override).
fn names_its_input(
    error: &ConfigError,
    keys: &[String],
    fragments: &[String],
) -> Result<(), TestCaseError> {
    for problem in error.problems() {
        let message = problem.to_string();
        let ok = match problem {
            ConfigError::UnknownKey { key, .. }
            | ConfigError::InvalidValue { key, .. }
            | ConfigError::WrongType { key, .. } => {
                keys.iter().any(|k| k.trim() == key) && message.contains(&format!("`{key}`"))
            }
            ConfigError::Toml { message, .. } => message.contains("line"),
            ConfigError::MalformedOverride { assignment } => {
                fragments.contains(assignment) && message.contains(assignment.as_str())
            }
            other => {
                return Err(TestCaseError::fail(format!(
                    "unexpected error kind: {other:?}"
                )))
            }
        };
        prop_assert!(ok, "the error does not name its input: {message}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(RunnerConfig { cases: CASES, failure_persistence: None, ..RunnerConfig::default() })]

    /// TOML documents: read, validated, or refused naming a key the document gave (or the line).
    #[test]
    fn fuzz_toml_documents_never_panic_or_hang_and_name_a_key(
        lines in proptest::collection::vec(line(), 0..8),
        separator in proptest::sample::select(vec!["\n", "\r\n", "\n\n"]),
    ) {
        let keys: Vec<String> = lines.iter().filter_map(|(k, _)| k.clone()).collect();
        let text = lines.iter().map(|(_, l)| l.as_str()).collect::<Vec<_>>().join(separator);
        let shown = text.clone();
        let result = bounded(shown.clone(), move || Config::from_toml_str(&text))?;
        match result {
            Ok(config) => prop_assert!(config.validate().is_ok(), "{shown}"),
            Err(error) => names_its_input(&error, &keys, &[])
                .map_err(|e| TestCaseError::fail(format!("{shown:?}: {e}")))?,
        }
    }

    /// `--set` overrides: read and validated together, or refused naming the key or the override.
    #[test]
    fn fuzz_set_overrides_never_panic_or_hang_and_name_a_key(
        sets in proptest::collection::vec(
            prop_oneof![
                5 => (key(), value(), "[ ]{0,2}", "[ ]{0,2}")
                    .prop_map(|(k, v, a, b)| (Some(k.clone()), format!("{a}{k}{b}={v}"))),
                1 => "[a-z =]{0,8}".prop_map(|s| (None, s)),
            ],
            0..6,
        ),
    ) {
        let keys: Vec<String> = sets.iter().filter_map(|(k, _)| k.clone()).collect();
        let fragments: Vec<String> = sets.iter().map(|(_, s)| s.clone()).collect();
        // A fragment's key is what precedes its `=`.
        let mut named = keys.clone();
        named.extend(fragments.iter().filter_map(|s| s.split_once('=').map(|(k, _)| k.trim().to_string())));
        let overrides = fragments.clone();
        let shown = format!("{fragments:?}");
        let result = bounded(shown.clone(), move || Config::load(None, &overrides))?;
        match result {
            Ok(config) => prop_assert!(config.validate().is_ok(), "{shown}"),
            Err(error) => names_its_input(&error, &named, &fragments)
                .map_err(|e| TestCaseError::fail(format!("{shown}: {e}")))?,
        }
    }
}
