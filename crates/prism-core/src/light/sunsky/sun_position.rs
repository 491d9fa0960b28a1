//! Where the sun is at a place and time: Blanco-Muriel, Alarcón-Padilla, López-Moratalla and
//! Lara-Coira 2001, "Computing the Solar Vector" (Solar Energy 70(5), 431–441), the PSA
//! algorithm, as Mitsuba 3's `sun_coordinates` implements it (with its parallax correction).

use std::f64::consts::{PI, TAU};

/// A place on Earth: degrees north and east, and the offset of its clock from UTC in hours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    pub latitude: f64,
    pub longitude: f64,
    pub timezone: f64,
}

/// A local date and time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DateTime {
    pub year: i64,
    pub month: i64,
    pub day: i64,
    pub hour: f64,
    pub minute: f64,
    pub second: f64,
}

/// Mean radius of the Earth and the astronomical unit, in km (for the parallax correction).
const EARTH_MEAN_RADIUS: f64 = 6371.01;
const ASTRONOMICAL_UNIT: f64 = 149_597_890.0;

/// The sun's zenith angle θ and azimuth φ (radians) in Mitsuba's emitter frame, where the
/// direction is (sin θ cos φ, sin θ sin φ, cos θ): the paper's azimuth (from north, through
/// east) minus π.
pub fn sun_angles(time: &DateTime, location: &Location) -> (f64, f64) {
    // Days since JD 2451545.0 (noon, 1 January 2000, UT); integer division truncates toward
    // zero, as the paper's C code does.
    let hours = time.hour - location.timezone + (time.minute + time.second / 60.0) / 60.0;
    let aux1 = (time.month - 14) / 12;
    let aux2 = (1461 * (time.year + 4800 + aux1)) / 4 + (367 * (time.month - 2 - 12 * aux1)) / 12
        - (3 * ((time.year + 4900 + aux1) / 100)) / 4
        + time.day
        - 32075;
    let julian_date = aux2 as f64 - 0.5 + hours / 24.0;
    let n = julian_date - 2_451_545.0;

    // Ecliptic coordinates.
    let omega = 2.1429 - 0.001_039_459_4 * n;
    let mean_longitude = 4.895_063_0 + 0.017_202_791_698 * n;
    let anomaly = 6.240_060_0 + 0.017_201_969_9 * n;
    let ecliptic_longitude =
        mean_longitude + 0.033_416_07 * anomaly.sin() + 0.000_348_94 * (2.0 * anomaly).sin()
            - 0.000_113_4
            - 0.000_020_3 * omega.sin();
    let obliquity = 0.409_092_8 - 6.2140e-9 * n + 0.000_039_6 * omega.cos();

    // Celestial coordinates.
    let sin_longitude = ecliptic_longitude.sin();
    let mut right_ascension = (obliquity.cos() * sin_longitude).atan2(ecliptic_longitude.cos());
    if right_ascension < 0.0 {
        right_ascension += TAU;
    }
    let declination = (obliquity.sin() * sin_longitude).asin();

    // Local coordinates.
    let gmst = 6.697_424_324_2 + 0.065_709_828_3 * n + hours;
    let lmst = (gmst * 15.0 + location.longitude).to_radians();
    let latitude = location.latitude.to_radians();
    let hour_angle = lmst - right_ascension;
    let mut zenith = (latitude.cos() * hour_angle.cos() * declination.cos()
        + declination.sin() * latitude.sin())
    .clamp(-1.0, 1.0)
    .acos();
    let mut azimuth = (-hour_angle.sin())
        .atan2(declination.tan() * latitude.cos() - latitude.sin() * hour_angle.cos());
    if azimuth < 0.0 {
        azimuth += TAU;
    }
    zenith += EARTH_MEAN_RADIUS / ASTRONOMICAL_UNIT * zenith.sin();
    (zenith, azimuth - PI)
}
