//! The serde deserializer that reads [`Params`](super::Params) and [`SolverOptions`](super::SolverOptions)
//! from a flat table of raw values, with the configuration's own errors.
//!
//! The type a value must have is the type serde asks for (the field's type): a real number for an `f64`
//! field (integers are accepted), a non-negative integer for a `usize`, `true` or `false` for a `bool`, one of
//! the variant names for a choice such as [`ImpactModel`](super::ImpactModel). So the text of a `--set key=value`
//! override is parsed by its key's type with no list of keys, and every error names its key: a value of the
//! wrong type is [`ConfigError::WrongType`], a name that is not one of a choice's values or a number that an
//! `f64` cannot hold is [`ConfigError::InvalidValue`], a key that is not a field is
//! [`ConfigError::UnknownKey`] listing every key.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, DeserializeOwned, DeserializeSeed, IntoDeserializer, MapAccess, Visitor};
use serde::forward_to_deserialize_any;

use super::{invalid, ConfigError};

/// One key's value on its way into a configuration, with where it came from.
#[derive(Debug, Clone)]
pub(crate) enum Raw {
    /// A value serialized from a configuration, read back as it is.
    Stored(toml::Value),
    /// A value the user gave: from a TOML document, with the text it was written as (to refuse `1e-400`,
    /// which toml reads as 0), or from a typed front such as the Python binding's keywords.
    Given(toml::Value, Option<String>),
    /// The text of a `--set key=value` override, parsed by the key's type.
    Text(String),
}

impl Raw {
    /// Whether the user gave this value (it did not come from a configuration's stored values).
    pub(crate) fn is_given(&self) -> bool {
        !matches!(self, Raw::Stored(_))
    }

    /// The value as shown in an error.
    fn shown(&self) -> String {
        match self {
            Raw::Text(text) => text.clone(),
            Raw::Stored(value) | Raw::Given(value, _) => value.to_string(),
        }
    }
}

/// A flat table of keys and raw values, in key order. Sources are merged into it one after the other (the
/// defaults or a configuration's stored values, a file, overrides), a later value replacing an earlier one.
pub(crate) type Table = BTreeMap<String, Raw>;

/// One key of a table and its value.
pub(crate) type Entry<'a> = (&'a str, &'a Raw);

/// Reads the struct `T` (whose fields are keys) from `entries`, in their order; the first error stops it.
pub(crate) fn read<T: DeserializeOwned>(entries: &[Entry<'_>]) -> Result<T, ConfigError> {
    let last_key = Cell::new("");
    let fields = Fields(Entries {
        entries: entries.iter(),
        value: None,
        last_key: &last_key,
    });
    T::deserialize(fields).map_err(|error| match error {
        ReadError::Config(error) => error,
        // Values wrap serde's own messages with their key (`Entries::next_value_seed`); what is left came
        // from the key last read.
        ReadError::Serde(reason) => invalid(last_key.get(), "", reason),
    })
}

/// The field names serde reads for the struct `T`, in declaration order: what its derived `Deserialize`
/// hands to `deserialize_struct`. Empty if `T` is not a struct.
pub(crate) fn field_names<T: DeserializeOwned>() -> &'static [&'static str] {
    /// A deserializer that only notes the field names it is asked for.
    struct Names<'a>(&'a mut &'static [&'static str]);

    impl<'de> de::Deserializer<'de> for Names<'_> {
        type Error = de::value::Error;

        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
            Err(de::Error::custom("not a struct"))
        }

        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _name: &'static str,
            fields: &'static [&'static str],
            _visitor: V,
        ) -> Result<V::Value, Self::Error> {
            *self.0 = fields;
            Err(de::Error::custom("only the field names are read"))
        }

        forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option unit
            unit_struct newtype_struct seq tuple tuple_struct map enum identifier ignored_any
        }
    }

    let mut fields: &'static [&'static str] = &[];
    // The error is the point: the names are noted before it.
    let _ = T::deserialize(Names(&mut fields));
    fields
}

/// An error while serde reads: the configuration's own, or a message of serde's.
#[derive(Debug)]
enum ReadError {
    /// An error with its key.
    Config(ConfigError),
    /// serde's message, given its key by [`Entries::next_value_seed`] (the value readers below produce only
    /// [`ReadError::Config`]; this is for visitors that refuse a value they were handed).
    Serde(String),
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadError::Config(error) => error.fmt(f),
            ReadError::Serde(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for ReadError {}

impl de::Error for ReadError {
    fn custom<T: fmt::Display>(message: T) -> Self {
        ReadError::Serde(message.to_string())
    }

    /// `deny_unknown_fields` refuses a key. The message lists every key of a configuration, not only the
    /// struct's: the reader of the whole table fills `known` in (`load.rs`, which knows both structs).
    fn unknown_field(field: &str, _expected: &'static [&'static str]) -> Self {
        ReadError::Config(ConfigError::UnknownKey {
            key: field.to_string(),
            known: String::new(),
        })
    }
}

impl From<ConfigError> for ReadError {
    fn from(error: ConfigError) -> Self {
        ReadError::Config(error)
    }
}

/// A table read as a struct.
struct Fields<'a>(Entries<'a>);

impl<'de> de::Deserializer<'de> for Fields<'_> {
    type Error = ReadError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        visitor.visit_map(self.0)
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf option unit
        unit_struct newtype_struct seq tuple tuple_struct map struct enum identifier ignored_any
    }
}

/// The entries of a table, handed to serde one key and value at a time.
struct Entries<'a> {
    /// The entries not read yet.
    entries: std::slice::Iter<'a, Entry<'a>>,
    /// The entry whose key was read and whose value is next.
    value: Option<Entry<'a>>,
    /// The key read last, for errors that come without one.
    last_key: &'a Cell<&'a str>,
}

impl<'de> MapAccess<'de> for Entries<'_> {
    type Error = ReadError;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, ReadError> {
        let Some(&(key, raw)) = self.entries.next() else {
            return Ok(None);
        };
        self.value = Some((key, raw));
        self.last_key.set(key);
        seed.deserialize(IntoDeserializer::<ReadError>::into_deserializer(key))
            .map(Some)
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, ReadError> {
        let (key, raw) = self
            .value
            .take()
            .ok_or_else(|| ReadError::Serde("a value was asked for before its key".to_string()))?;
        seed.deserialize(Value { key, raw })
            .map_err(|error| match error {
                ReadError::Serde(reason) => ReadError::Config(invalid(key, raw.shown(), reason)),
                error => error,
            })
    }
}

/// Expected type of a real-valued key, as shown in [`ConfigError::WrongType`].
const EXPECTED_REAL: &str = "a real number";
/// Expected type of an integer key, as shown in [`ConfigError::WrongType`].
const EXPECTED_COUNT: &str = "a non-negative integer";
/// Expected type of a boolean key, as shown in [`ConfigError::WrongType`].
const EXPECTED_FLAG: &str = "true or false";

/// The value of one key, read by the type serde asks for.
struct Value<'a> {
    /// The key, for errors.
    key: &'a str,
    /// The value.
    raw: &'a Raw,
}

impl Value<'_> {
    /// A [`ConfigError::WrongType`] for this key.
    fn wrong_type(&self, expected: impl Into<String>) -> ConfigError {
        let found = match self.raw {
            Raw::Text(text) => format!("{text:?}"),
            Raw::Stored(value) | Raw::Given(value, _) => describe(value),
        };
        ConfigError::WrongType {
            key: self.key.to_string(),
            expected: expected.into(),
            found,
        }
    }

    /// A real number; integers are accepted.
    fn real(&self) -> Result<f64, ConfigError> {
        match self.raw {
            Raw::Text(text) => match text.parse() {
                Ok(x) => literal(self.key, text, x),
                Err(_) => Err(self.wrong_type(EXPECTED_REAL)),
            },
            Raw::Given(toml::Value::Float(x), Some(text)) => literal(self.key, text, *x),
            Raw::Stored(toml::Value::Float(x)) | Raw::Given(toml::Value::Float(x), None) => Ok(*x),
            Raw::Stored(toml::Value::Integer(n)) | Raw::Given(toml::Value::Integer(n), _) => {
                Ok(*n as f64)
            }
            _ => Err(self.wrong_type(EXPECTED_REAL)),
        }
    }

    /// A non-negative integer.
    fn count(&self) -> Result<u64, ConfigError> {
        let n = match self.raw {
            Raw::Text(text) => match text.parse::<i64>() {
                Ok(n) => n,
                Err(error)
                    if matches!(
                        error.kind(),
                        std::num::IntErrorKind::PosOverflow | std::num::IntErrorKind::NegOverflow
                    ) =>
                {
                    return Err(invalid(self.key, text, "is out of range"))
                }
                Err(_) => return Err(self.wrong_type(EXPECTED_COUNT)),
            },
            Raw::Stored(toml::Value::Integer(n)) | Raw::Given(toml::Value::Integer(n), _) => *n,
            _ => return Err(self.wrong_type(EXPECTED_COUNT)),
        };
        u64::try_from(n).map_err(|_| invalid(self.key, n, "must be a non-negative integer"))
    }

    /// `true` or `false`.
    fn flag(&self) -> Result<bool, ConfigError> {
        match self.raw {
            Raw::Text(text) => text.parse().map_err(|_| self.wrong_type(EXPECTED_FLAG)),
            Raw::Stored(toml::Value::Boolean(b)) | Raw::Given(toml::Value::Boolean(b), _) => Ok(*b),
            _ => Err(self.wrong_type(EXPECTED_FLAG)),
        }
    }

    /// One of `names` (a choice's variant names, as serde spells them).
    fn choice(&self, names: &'static [&'static str]) -> Result<&str, ConfigError> {
        let expected = || {
            let quoted: Vec<String> = names.iter().map(|name| format!("{name:?}")).collect();
            match quoted.split_last() {
                Some((last, [])) => format!("the string {last}"),
                Some((last, rest)) => format!("the string {} or {last}", rest.join(", ")),
                None => "nothing".to_string(),
            }
        };
        let name = match self.raw {
            Raw::Text(text) => text.as_str(),
            Raw::Stored(toml::Value::String(name)) | Raw::Given(toml::Value::String(name), _) => {
                name.as_str()
            }
            _ => return Err(self.wrong_type(expected())),
        };
        if names.contains(&name) {
            Ok(name)
        } else {
            Err(invalid(
                self.key,
                format!("{name:?}"),
                format!("must be {}", expected()),
            ))
        }
    }
}

impl<'de> de::Deserializer<'de> for Value<'_> {
    type Error = ReadError;

    /// Only for field types the configuration does not have (yet): the value as it is.
    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        match self.raw {
            Raw::Text(text) => visitor.visit_str(text),
            Raw::Stored(value) | Raw::Given(value, _) => match value {
                toml::Value::String(s) => visitor.visit_str(s),
                toml::Value::Integer(n) => visitor.visit_i64(*n),
                toml::Value::Float(x) => visitor.visit_f64(*x),
                toml::Value::Boolean(b) => visitor.visit_bool(*b),
                _ => Err(self.wrong_type("a number, a boolean or a string").into()),
            },
        }
    }

    fn deserialize_f64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        visitor.visit_f64(self.real()?)
    }

    fn deserialize_f32<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        self.deserialize_f64(visitor)
    }

    /// `usize` fields are read here too.
    fn deserialize_u64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        visitor.visit_u64(self.count()?)
    }

    fn deserialize_u32<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        self.deserialize_u64(visitor)
    }

    fn deserialize_bool<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ReadError> {
        visitor.visit_bool(self.flag()?)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, ReadError> {
        let name = self.choice(variants)?;
        visitor.visit_enum(IntoDeserializer::<ReadError>::into_deserializer(name))
    }

    forward_to_deserialize_any! {
        i8 i16 i32 i64 i128 u8 u16 u128 char str string bytes byte_buf option unit unit_struct
        newtype_struct seq tuple tuple_struct map struct identifier ignored_any
    }
}

/// The real number `x` read from `text`, refused when the text names a finite non-zero number that an `f64`
/// cannot hold (it would silently become infinite or 0). Non-finite spellings (`inf`, `nan`) pass here and
/// are refused by validation, which names the key.
pub(crate) fn literal(key: &str, text: &str, x: f64) -> Result<f64, ConfigError> {
    let mantissa = text.split(['e', 'E']).next().unwrap_or(text);
    if x.is_infinite() && !text.to_ascii_lowercase().contains("inf") {
        Err(invalid(
            key,
            text,
            "is too large for a 64-bit float (the largest is about 1.8e308)",
        ))
    } else if x == 0.0 && mantissa.bytes().any(|b| (b'1'..=b'9').contains(&b)) {
        Err(invalid(
            key,
            text,
            "is too small for a 64-bit float: it would be read as 0 (the smallest is about 4.9e-324)",
        ))
    } else {
        Ok(x)
    }
}

/// A TOML value's type and value, for [`ConfigError::WrongType`].
fn describe(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => format!("the string {s:?}"),
        toml::Value::Integer(n) => format!("the integer {n}"),
        toml::Value::Float(x) => format!("the float {x}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Datetime(d) => format!("the datetime {d}"),
        toml::Value::Array(_) => "an array".to_string(),
        toml::Value::Table(_) => "a table (the file must be flat: no [sections])".to_string(),
    }
}
