//! The output guard: no NaN or infinity reaches a file lodeval writes. Every table row and JSON
//! report passes through [`check`] before it is written; a non-finite number there is a lodeval
//! bug (inputs that could cause one are refused when read, see `src/limits.rs`), reported as an
//! internal error naming the field, instead of a `NaN` a spreadsheet or a gate would read as a
//! number.
//!
//! Decision: the check walks the value with serde (a serializer that only looks at numbers), so
//! it holds for every row type without a hand-written list of float fields, and names the field
//! by its serde name.

use serde::Serialize;
use serde::ser::{self, Impossible};

/// `Ok` when every `f32` and `f64` inside `value` is finite; else the name of the first field that
/// is not, with its value ("imperceptible_beyond_m = inf").
pub fn check<T: Serialize + ?Sized>(value: &T) -> Result<(), String> {
    value
        .serialize(&mut Finder { field: "value" })
        .map_err(|e| e.0)
}

/// The serializer: remembers the field it is in and fails on a non-finite float.
struct Finder {
    field: &'static str,
}

/// What [`Finder`] reports.
#[derive(Debug)]
struct Found(String);

impl std::fmt::Display for Found {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Found {}

impl ser::Error for Found {
    fn custom<M: std::fmt::Display>(msg: M) -> Self {
        Found(msg.to_string())
    }
}

impl Finder {
    fn float(&self, v: f64) -> Result<(), Found> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(Found(format!("{} = {v}", self.field)))
        }
    }
}

/// Serializer methods that accept a value and look no further.
macro_rules! accept {
    ($($name:ident($t:ty)),* $(,)?) => {
        $(fn $name(self, _: $t) -> Result<(), Found> { Ok(()) })*
    };
}

impl ser::Serializer for &mut Finder {
    type Ok = ();
    type Error = Found;
    type SerializeSeq = Self;
    type SerializeTuple = Self;
    type SerializeTupleStruct = Self;
    type SerializeTupleVariant = Self;
    type SerializeMap = Self;
    type SerializeStruct = Self;
    type SerializeStructVariant = Impossible<(), Found>;

    accept!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_unit_struct(&'static str),
    );

    fn serialize_f32(self, v: f32) -> Result<(), Found> {
        self.float(v as f64)
    }
    fn serialize_f64(self, v: f64) -> Result<(), Found> {
        self.float(v)
    }
    fn serialize_none(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_tuple(self, _: usize) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self, Found> {
        Ok(self)
    }
    fn serialize_struct_variant(
        self,
        name: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Found> {
        Err(Found(format!("{name}: struct variants are not checked")))
    }
}

/// Elements of sequences, tuples and maps: checked in turn, under the enclosing field's name.
macro_rules! elements {
    ($($trait:ident :: $method:ident),* $(,)?) => {
        $(impl ser::$trait for &mut Finder {
            type Ok = ();
            type Error = Found;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
                value.serialize(&mut **self)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        })*
    };
}

elements!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field,
);

impl ser::SerializeMap for &mut Finder {
    type Ok = ();
    type Error = Found;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Found> {
        key.serialize(&mut **self)
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
        value.serialize(&mut **self)
    }
    fn end(self) -> Result<(), Found> {
        Ok(())
    }
}

impl ser::SerializeStruct for &mut Finder {
    type Ok = ();
    type Error = Found;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        let outer = std::mem::replace(&mut self.field, key);
        let result = value.serialize(&mut **self);
        self.field = outer;
        result
    }
    fn end(self) -> Result<(), Found> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Row {
        name: String,
        value: f64,
        maybe: Option<f32>,
        list: Vec<f64>,
    }

    #[test]
    fn finds_the_first_non_finite_field() {
        let row = |value, maybe, list| Row {
            name: "inf".into(), // a name that reads like a number is not a number
            value,
            maybe,
            list,
        };
        assert!(check(&row(1.0, Some(2.0), vec![3.0])).is_ok());
        assert!(check(&row(1.0, None, vec![])).is_ok());
        assert_eq!(
            check(&row(f64::INFINITY, None, vec![])).unwrap_err(),
            "value = inf"
        );
        assert_eq!(
            check(&row(1.0, Some(f32::NAN), vec![])).unwrap_err(),
            "maybe = NaN"
        );
        assert_eq!(
            check(&row(1.0, None, vec![0.0, f64::NEG_INFINITY])).unwrap_err(),
            "list = -inf"
        );
        assert!(check(&[1.0f64, f64::NAN]).is_err());
    }
}
