//! Mitsuba 3 XML scenes: the XML reader, the parsed description and checked parameter access.
pub mod description;
mod element;
pub mod params;
mod property_values;
pub mod reader;
mod substitution;
mod transform_ops;
