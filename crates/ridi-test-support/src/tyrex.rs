//! The synthetic Tyrex run of `ridi-data`'s Tyrex tests and of the Tyrex fuzz seeds of
//! `cargo xtask fuzz`: the phone lies flat, turns about the room's z at [`TYREX_OMEGA`] and
//! moves along room x at 1 m/s; mocap time = phone time + [`TYREX_TIME_DIFF`]. Text rows and
//! mocap frames only: the files around them are each user's (they differ in rate, length and
//! what each test breaks).

use std::fmt::Write as _;
use std::ops::Range;

use ridi_frames::WorldFromDevice;
use ridi_frames::nalgebra::Vector3;

/// Turn rate of the synthetic run about the room's z, rad/s.
pub const TYREX_OMEGA: f64 = 0.3;

/// The run's `timeAlignment.txt`: mocap time = phone time + this, s.
pub const TYREX_TIME_DIFF: f64 = -2.0;

/// The rotation by `a` rad about z.
pub fn yaw(a: f64) -> WorldFromDevice {
    WorldFromDevice::from_axis_angle(&Vector3::z_axis(), a)
}

/// Rows of a phone file, `row(t)` at each phone time `t`: `hz` rows a second for `seconds`,
/// from 0.003 s.
pub fn tyrex_phone_rows(hz: f64, seconds: f64, row: impl Fn(f64) -> String) -> String {
    let mut s = String::new();
    for k in 0..(seconds * hz) as usize {
        let t = 0.003 + k as f64 / hz;
        writeln!(s, "{}", row(t)).expect("writing to a string");
    }
    s
}

/// `n` mocap frames at 60 Hz from mocap time 0, for [`qtm_take`](crate::qtm_take): positions
/// (mm) and rotations (column-major 3x3, the turn at [`TYREX_OMEGA`] in mocap time), the
/// frames in `lost` NaN as QTM writes a lost body.
pub fn tyrex_mocap(n: usize, lost: &[Range<usize>]) -> (Vec<[f64; 3]>, Vec<[f64; 9]>) {
    let mut p = Vec::new();
    let mut r = Vec::new();
    for i in 0..n {
        if lost.iter().any(|l| l.contains(&i)) {
            p.push([f64::NAN; 3]);
            r.push([f64::NAN; 9]);
            continue;
        }
        let t = i as f64 / 60.0;
        p.push([t * 1000.0, 500.0, 1200.0]);
        let m = yaw(TYREX_OMEGA * t).matrix();
        r.push(m.as_slice().try_into().expect("a 3x3 matrix"));
    }
    (p, r)
}
