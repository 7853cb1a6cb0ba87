//! The messages of haptic devices' ROS 2 drivers, beyond the common ones of [`crate::msg`]:
//! a pose a driver measures (`PoseStamped`, decoded), the clutch as a `std_msgs/Bool`
//! (Force Dimension's `/fd/fd_clutch`), a `sensor_msgs/Joy` button (CRTK's), and the
//! omni_common drivers' own `omni_msgs` (`OmniButtonEvent`, `OmniFeedback`), with their
//! definitions as the drivers' `.msg` files give them. Every type both ways: the loop
//! decodes what devices send and encodes what it sends them; tests and stand-ins use the
//! other direction.

use crate::cdr::{CdrError, CdrReader, CdrWriter};
use crate::msg::{read_vec3, vec3, Decode, Header, Message, PoseStamped};

impl Decode for PoseStamped {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(PoseStamped {
            header: Header::decode(r)?,
            position: read_vec3(r)?,
            orientation: [r.f64()?, r.f64()?, r.f64()?, r.f64()?],
        })
    }
}

/// `std_msgs/msg/Bool`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Bool {
    /// The value.
    pub data: bool,
}

impl Message for Bool {
    const TYPE: &'static str = "std_msgs/msg/Bool";
    fn encode(&self, w: &mut CdrWriter) {
        w.bool(self.data);
    }
}

impl Decode for Bool {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Bool { data: r.bool()? })
    }
}

/// `sensor_msgs/msg/Joy`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Joy {
    /// Stamp and frame.
    pub header: Header,
    /// The axes.
    pub axes: Vec<f32>,
    /// The buttons (CRTK: 1 pressed, 0 released, 2 clicked).
    pub buttons: Vec<i32>,
}

impl Message for Joy {
    const TYPE: &'static str = "sensor_msgs/msg/Joy";
    fn encode(&self, w: &mut CdrWriter) {
        self.header.encode(w);
        w.seq_len(self.axes.len());
        self.axes.iter().for_each(|a| w.f32(*a));
        w.seq_len(self.buttons.len());
        self.buttons.iter().for_each(|b| w.i32(*b));
    }
}

impl Decode for Joy {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let header = Header::decode(r)?;
        // Counts are bounded by the reader's limit: a malformed one allocates nothing.
        let n = r.seq_len()?;
        let axes = (0..n).map(|_| r.f32()).collect::<Result<_, _>>()?;
        let n = r.seq_len()?;
        let buttons = (0..n).map(|_| r.i32()).collect::<Result<_, _>>()?;
        Ok(Joy {
            header,
            axes,
            buttons,
        })
    }
}

/// `omni_msgs/msg/OmniButtonEvent`: the Touch's two stylus buttons, 1 pressed, sent by
/// the omni_common drivers only when one changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OmniButtonEvent {
    /// The grey (front) button.
    pub grey_button: i32,
    /// The white (back) button.
    pub white_button: i32,
}

impl Message for OmniButtonEvent {
    const TYPE: &'static str = "omni_msgs/msg/OmniButtonEvent";
    fn encode(&self, w: &mut CdrWriter) {
        w.i32(self.grey_button);
        w.i32(self.white_button);
    }
}

impl Decode for OmniButtonEvent {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(OmniButtonEvent {
            grey_button: r.i32()?,
            white_button: r.i32()?,
        })
    }
}

/// `omni_msgs/msg/OmniFeedback`: the force the omni_common drivers render (N, in the
/// frame they publish the pose in) and a lock position they do not use.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OmniFeedback {
    /// The force, N.
    pub force: [f64; 3],
    /// The position to hold the handle at (unused by the drivers), m.
    pub position: [f64; 3],
}

impl Message for OmniFeedback {
    const TYPE: &'static str = "omni_msgs/msg/OmniFeedback";
    fn encode(&self, w: &mut CdrWriter) {
        vec3(w, &self.force);
        vec3(w, &self.position);
    }
}

impl Decode for OmniFeedback {
    fn decode(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(OmniFeedback {
            force: read_vec3(r)?,
            position: read_vec3(r)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_message_reads_back_what_it_wrote() {
        let p = PoseStamped {
            header: Header::at(1_500_000_000, "fd_base"),
            position: [0.01, -0.02, 0.03],
            orientation: [0.0, 0.0, 0.6, 0.8],
        };
        assert_eq!(PoseStamped::from_cdr(&p.to_cdr()), Ok(p));
        for data in [false, true] {
            assert_eq!(Bool::from_cdr(&Bool { data }.to_cdr()), Ok(Bool { data }));
        }
        let j = Joy {
            header: Header::at(7, ""),
            axes: vec![],
            buttons: vec![1],
        };
        assert_eq!(Joy::from_cdr(&j.to_cdr()), Ok(j));
        let b = OmniButtonEvent {
            grey_button: 1,
            white_button: 0,
        };
        assert_eq!(OmniButtonEvent::from_cdr(&b.to_cdr()), Ok(b));
        let f = OmniFeedback {
            force: [1.0, -2.0, 0.5],
            position: [0.0; 3],
        };
        assert_eq!(OmniFeedback::from_cdr(&f.to_cdr()), Ok(f));
    }

    #[test]
    fn malformed_bytes_are_errors() {
        assert!(Bool::from_cdr(&[0, 1, 0, 0]).is_err(), "no value");
        assert!(OmniButtonEvent::from_cdr(&[0, 1, 0, 0, 1, 0, 0, 0]).is_err());
        // A Joy claiming a billion buttons.
        let mut w = CdrWriter::new();
        Header::at(0, "").encode(&mut w);
        w.seq_len(0);
        w.u32(1_000_000_000);
        assert!(Joy::from_cdr(w.bytes()).is_err());
    }
}
