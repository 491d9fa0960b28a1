//! Mitsuba 3 XML scenes: the parsed description and checked parameter access.
pub mod description;
pub mod params;
