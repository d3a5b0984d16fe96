//! Whether a value already serializes with the keys of every object in alphabetical order, as
//! the result's sorted sections are written ([`super::result_sections::sorted`]).
//!
//! Such a value is written directly; any other goes through a `serde_json::Value`, whose maps
//! sort their keys. Both give the same text when the keys come sorted and each once (a `Value`
//! only reorders and merges keys), so this check decides the speed, never the bytes. It walks
//! the value without writing anything: no number is formatted, no key allocated except a map's
//! (a struct's field names are static).
//!
//! What a `Value` would write differently beyond key order is refused too, so that the direct
//! path is taken only where the text is certainly the same: `f32` (a `Value` widens it to `f64`
//! and writes more digits), 128-bit integers and bytes.

use serde::ser::{self, Impossible, Serialize};
use std::fmt;

/// Whether `v` serializes with every object's keys strictly increasing (alphabetical, each once)
/// and nothing a `serde_json::Value` would write otherwise.
pub(crate) fn keys_sorted<T: Serialize + ?Sized>(v: &T) -> bool {
    v.serialize(Walk).is_ok()
}

/// Why a value is not written directly (never shown: the caller falls back to a `Value`).
#[derive(Debug)]
pub(crate) struct NotSorted;

impl fmt::Display for NotSorted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("keys not in alphabetical order")
    }
}

impl std::error::Error for NotSorted {}

impl ser::Error for NotSorted {
    fn custom<T: fmt::Display>(_msg: T) -> Self {
        NotSorted
    }
}

type R = Result<(), NotSorted>;

/// The walking serializer: checks, writes nothing.
struct Walk;

/// An object being walked: the last key, to compare the next with.
struct Object {
    /// The last struct field name.
    last_field: Option<&'static str>,
    /// The last map key (a map's keys, a flattened struct's included, are not static).
    last_key: Option<String>,
    /// The key being read (reused between keys).
    key: String,
}

impl Object {
    fn new() -> Object {
        Object {
            last_field: None,
            last_key: None,
            key: String::new(),
        }
    }

    fn field(&mut self, name: &'static str) -> R {
        match self.last_field {
            Some(last) if last >= name => Err(NotSorted),
            _ => {
                self.last_field = Some(name);
                Ok(())
            }
        }
    }
}

impl ser::Serializer for Walk {
    type Ok = ();
    type Error = NotSorted;
    type SerializeSeq = Walk;
    type SerializeTuple = Walk;
    type SerializeTupleStruct = Walk;
    type SerializeTupleVariant = Walk;
    type SerializeMap = Object;
    type SerializeStruct = Object;
    type SerializeStructVariant = Object;

    fn serialize_bool(self, _: bool) -> R {
        Ok(())
    }
    fn serialize_i8(self, _: i8) -> R {
        Ok(())
    }
    fn serialize_i16(self, _: i16) -> R {
        Ok(())
    }
    fn serialize_i32(self, _: i32) -> R {
        Ok(())
    }
    fn serialize_i64(self, _: i64) -> R {
        Ok(())
    }
    fn serialize_u8(self, _: u8) -> R {
        Ok(())
    }
    fn serialize_u16(self, _: u16) -> R {
        Ok(())
    }
    fn serialize_u32(self, _: u32) -> R {
        Ok(())
    }
    fn serialize_u64(self, _: u64) -> R {
        Ok(())
    }
    fn serialize_i128(self, _: i128) -> R {
        Err(NotSorted)
    }
    fn serialize_u128(self, _: u128) -> R {
        Err(NotSorted)
    }
    fn serialize_f32(self, _: f32) -> R {
        Err(NotSorted)
    }
    fn serialize_f64(self, _: f64) -> R {
        Ok(())
    }
    fn serialize_char(self, _: char) -> R {
        Ok(())
    }
    fn serialize_str(self, _: &str) -> R {
        Ok(())
    }
    fn serialize_bytes(self, _: &[u8]) -> R {
        Err(NotSorted)
    }
    fn serialize_none(self) -> R {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn serialize_unit(self) -> R {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> R {
        v.serialize(Walk)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        v: &T,
    ) -> R {
        v.serialize(Walk)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Walk, NotSorted> {
        Ok(Walk)
    }
    fn serialize_tuple(self, _: usize) -> Result<Walk, NotSorted> {
        Ok(Walk)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Walk, NotSorted> {
        Ok(Walk)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Walk, NotSorted> {
        Ok(Walk)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Object, NotSorted> {
        Ok(Object::new())
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Object, NotSorted> {
        Ok(Object::new())
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Object, NotSorted> {
        Ok(Object::new())
    }
}

impl ser::SerializeSeq for Walk {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTuple for Walk {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTupleStruct for Walk {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTupleVariant for Walk {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeStruct for Object {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, name: &'static str, v: &T) -> R {
        self.field(name)?;
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeStructVariant for Object {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, name: &'static str, v: &T) -> R {
        self.field(name)?;
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeMap for Object {
    type Ok = ();
    type Error = NotSorted;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> R {
        self.key.clear();
        k.serialize(Key(&mut self.key))?;
        if self
            .last_key
            .as_deref()
            .is_some_and(|l| l >= self.key.as_str())
        {
            return Err(NotSorted);
        }
        match &mut self.last_key {
            Some(last) => std::mem::swap(last, &mut self.key),
            None => self.last_key = Some(std::mem::take(&mut self.key)),
        }
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(Walk)
    }
    fn end(self) -> R {
        Ok(())
    }
}

/// A map key as the text serde_json writes it: strings, characters and integers (which it
/// quotes); anything else is left to the `Value` path.
struct Key<'a>(&'a mut String);

macro_rules! integer_key {
    ($($f:ident: $t:ty),*) => {$(
        fn $f(self, v: $t) -> R {
            self.0.push_str(&v.to_string());
            Ok(())
        }
    )*};
}

impl ser::Serializer for Key<'_> {
    type Ok = ();
    type Error = NotSorted;
    type SerializeSeq = Impossible<(), NotSorted>;
    type SerializeTuple = Impossible<(), NotSorted>;
    type SerializeTupleStruct = Impossible<(), NotSorted>;
    type SerializeTupleVariant = Impossible<(), NotSorted>;
    type SerializeMap = Impossible<(), NotSorted>;
    type SerializeStruct = Impossible<(), NotSorted>;
    type SerializeStructVariant = Impossible<(), NotSorted>;

    integer_key!(serialize_i8: i8, serialize_i16: i16, serialize_i32: i32, serialize_i64: i64,
        serialize_u8: u8, serialize_u16: u16, serialize_u32: u32, serialize_u64: u64);

    fn serialize_str(self, v: &str) -> R {
        self.0.push_str(v);
        Ok(())
    }
    fn serialize_char(self, v: char) -> R {
        self.0.push(v);
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, variant: &'static str) -> R {
        self.0.push_str(variant);
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> R {
        v.serialize(self)
    }
    fn serialize_bool(self, _: bool) -> R {
        Err(NotSorted)
    }
    fn serialize_i128(self, _: i128) -> R {
        Err(NotSorted)
    }
    fn serialize_u128(self, _: u128) -> R {
        Err(NotSorted)
    }
    fn serialize_f32(self, _: f32) -> R {
        Err(NotSorted)
    }
    fn serialize_f64(self, _: f64) -> R {
        Err(NotSorted)
    }
    fn serialize_bytes(self, _: &[u8]) -> R {
        Err(NotSorted)
    }
    fn serialize_none(self) -> R {
        Err(NotSorted)
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> R {
        Err(NotSorted)
    }
    fn serialize_unit(self) -> R {
        Err(NotSorted)
    }
    fn serialize_unit_struct(self, _: &'static str) -> R {
        Err(NotSorted)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> R {
        Err(NotSorted)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStruct, NotSorted> {
        Err(NotSorted)
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, NotSorted> {
        Err(NotSorted)
    }
}

#[cfg(test)]
mod tests {
    use super::keys_sorted;
    use serde::Serialize;
    use serde_json::json;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Sorted {
        a: f64,
        b: Vec<Inner>,
        c: Option<u8>,
    }

    #[derive(Serialize)]
    struct Inner {
        x: f64,
        y: f64,
    }

    #[derive(Serialize)]
    struct Unsorted {
        b: f64,
        a: f64,
    }

    #[derive(Serialize)]
    struct Nested {
        a: Vec<Unsorted>,
    }

    #[derive(Serialize)]
    struct Flat {
        m: u8,
        #[serde(flatten)]
        rest: BTreeMap<String, u8>,
    }

    #[test]
    fn sorted_values_pass_and_any_disorder_anywhere_fails() {
        let inner = || Inner { x: 1.0, y: 2.0 };
        let s = Sorted {
            a: 1.0,
            b: vec![inner(), inner()],
            c: None,
        };
        assert!(keys_sorted(&s));
        assert!(!keys_sorted(&Unsorted { b: 1.0, a: 2.0 }));
        assert!(!keys_sorted(&Nested {
            a: vec![Unsorted { b: 1.0, a: 2.0 }]
        }));
        // A Value's maps are sorted; a map's keys are compared as text, integers included.
        assert!(keys_sorted(
            &json!({"b": {"z": 1, "a0": [{"q": 1}]}, "a": 2})
        ));
        let ints: indexmap::IndexMap<u32, u8> = [(10, 1), (9, 2)].into_iter().collect();
        assert!(keys_sorted(&ints), "\"10\" < \"9\" as text");
        let ints: indexmap::IndexMap<u32, u8> = [(9, 1), (10, 2)].into_iter().collect();
        assert!(!keys_sorted(&ints));
        // A flattened map continues the struct's keys: compared with its fields too.
        let rest = |k: &str| [(k.to_owned(), 1)].into_iter().collect();
        assert!(keys_sorted(&Flat {
            m: 1,
            rest: rest("n")
        }));
        assert!(!keys_sorted(&Flat {
            m: 1,
            rest: rest("a")
        }));
        assert!(!keys_sorted(&Flat {
            m: 1,
            rest: rest("m")
        }));
        // What a Value would write differently is refused.
        assert!(!keys_sorted(&1.5f32));
        assert!(!keys_sorted(&1u128));
    }
}
