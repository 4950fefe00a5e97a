//! One file per G-code dialect, each implementing [`Rules`](super::writer::Rules); adding a
//! controller is a new file here, its variant in [`Dialect`](super::Dialect) and one line in
//! [`Dialect::rules`](super::Dialect::rules).

mod fanuc;
mod generic;
mod heidenhain;
mod linuxcnc;
mod linuxcnc_tcp;
mod sinumerik;

pub(super) use fanuc::Fanuc;
pub(super) use generic::Generic;
pub(super) use heidenhain::Heidenhain;
pub(super) use linuxcnc::Linuxcnc;
pub(super) use linuxcnc_tcp::LinuxcncTcp;
pub use linuxcnc_tcp::{linuxcnc_kinematics, LinuxcncKinematics};
pub(super) use sinumerik::Sinumerik;
