//! An arm's joint values, any count up to [`MAX_JOINTS`], held inline.
//!
//! One type for the paper's three joints and a URDF arm's N: the slave's arm, its real
//! robot, the robot's gate and the record all carry it, and copying it costs no heap,
//! so a sample's joints move through the loop without an allocation.

use serde::de::{Deserializer, SeqAccess, Visitor};
use serde::ser::{SerializeSeq, Serializer};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Deref, DerefMut};

/// The most joints an arm may have (a 7-joint arm on a 6-joint base is 13).
pub const MAX_JOINTS: usize = 16;

/// Joint values (rad for a revolute joint, m for a prismatic one), in the arm's order.
///
/// ```
/// use tactile_math::joints::Joints;
/// let q = Joints::from_slice(&[0.1, -0.2]).unwrap();
/// assert_eq!(q.len(), 2);
/// assert_eq!(&q[..], &[0.1, -0.2]);
/// assert_eq!(Joints::from([1.0, 2.0, 3.0]).to_array3(), [1.0, 2.0, 3.0]);
/// assert!(Joints::from_slice(&[0.0; 17]).is_err());
/// ```
#[derive(Clone, Copy, PartialEq, Default)]
pub struct Joints {
    len: u8,
    /// Unused slots stay zero, so the derived equality is the slices'.
    values: [f64; MAX_JOINTS],
}

/// More joints than a [`Joints`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{0} joints: an arm may have at most {MAX_JOINTS}")]
pub struct TooManyJoints(pub usize);

impl Joints {
    /// The values of `q`, if there are at most [`MAX_JOINTS`].
    pub fn from_slice(q: &[f64]) -> Result<Joints, TooManyJoints> {
        let mut j = Joints::zeros(q.len())?;
        j.values[..q.len()].copy_from_slice(q);
        Ok(j)
    }

    /// `n` zeros, if `n` is at most [`MAX_JOINTS`].
    pub fn zeros(n: usize) -> Result<Joints, TooManyJoints> {
        if n > MAX_JOINTS {
            return Err(TooManyJoints(n));
        }
        Ok(Joints {
            len: n as u8,
            values: [0.0; MAX_JOINTS],
        })
    }

    /// The first three values (zero where there are fewer): the paper's arm's angles.
    pub fn to_array3(&self) -> [f64; 3] {
        [self.values[0], self.values[1], self.values[2]]
    }
}

impl From<[f64; 3]> for Joints {
    fn from(theta: [f64; 3]) -> Joints {
        let mut values = [0.0; MAX_JOINTS];
        values[..3].copy_from_slice(&theta);
        Joints { len: 3, values }
    }
}

impl Deref for Joints {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..usize::from(self.len)]
    }
}

impl DerefMut for Joints {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..usize::from(self.len)]
    }
}

impl<'a> IntoIterator for &'a Joints {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl AsRef<[f64]> for Joints {
    fn as_ref(&self) -> &[f64] {
        self
    }
}

impl AsMut<[f64]> for Joints {
    fn as_mut(&mut self) -> &mut [f64] {
        self
    }
}

/// Written as a sequence, as a `Vec<f64>` is: a record's bytes are the same either way.
impl Serialize for Joints {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.len()))?;
        for v in self.iter() {
            seq.serialize_element(v)?;
        }
        seq.end()
    }
}

/// Read as a sequence of at most [`MAX_JOINTS`] numbers; a longer one is refused.
impl<'de> Deserialize<'de> for Joints {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Joints, D::Error> {
        d.deserialize_seq(JointsVisitor)
    }
}

struct JointsVisitor;

impl<'de> Visitor<'de> for JointsVisitor {
    type Value = Joints;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "at most {MAX_JOINTS} joint values")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Joints, A::Error> {
        let mut j = Joints::default();
        while let Some(v) = seq.next_element::<f64>()? {
            let n = usize::from(j.len);
            if n == MAX_JOINTS {
                return Err(serde::de::Error::invalid_length(n + 1, &self));
            }
            j.values[n] = v;
            j.len += 1;
        }
        Ok(j)
    }
}

impl fmt::Debug for Joints {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slice_round_trips_and_the_unused_slots_do_not_count() {
        let a = Joints::from_slice(&[1.0, 2.0]).expect("two");
        let mut b = Joints::from_slice(&[1.0, 2.0]).expect("two");
        assert_eq!(a, b);
        b[1] = 3.0;
        assert_ne!(a, b);
        assert_eq!(format!("{a:?}"), "[1.0, 2.0]");
        assert_eq!(Joints::zeros(MAX_JOINTS).expect("max").len(), MAX_JOINTS);
        assert_eq!(Joints::zeros(MAX_JOINTS + 1), Err(TooManyJoints(17)));
        assert_eq!(Joints::default().len(), 0);
    }

    #[test]
    fn it_is_written_as_a_vec_is_and_a_longer_one_is_refused() {
        let q = Joints::from_slice(&[0.5, -1.0, 2.0]).expect("three");
        let as_vec = toml::Value::try_from(vec![0.5, -1.0, 2.0]).expect("vec");
        assert_eq!(toml::Value::try_from(q).expect("joints"), as_vec);
        let back: Joints = as_vec.try_into().expect("read back");
        assert_eq!(back, q);
        let long = toml::Value::try_from(vec![0.0; MAX_JOINTS + 1]).expect("vec");
        let e = Joints::deserialize(long).expect_err("too long");
        assert!(e.to_string().contains("at most 16 joint values"), "{e}");
    }
}
