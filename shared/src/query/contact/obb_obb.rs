//! Contact between an oriented box and an oriented box.

use super::{sat::sat, Contact, Proximity};
use crate::shape::Obb;
use glam::IVec2;

impl Contact<Obb> for Obb {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Obb, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::Obb;

    /// u = (30, 40), v = (-20, 15): n1 = (40, -30) faces at 25 units, n2 =
    /// (15, 20) faces at 50 units.
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    /// A square turned 45 degrees (u = (35, 35), v = (-35, 35)) and an
    /// upright 60 x 40 box.
    fn diamond() -> Obb {
        let o = Obb::new(v(50, 50), v(1, 1)).unwrap();
        assert_eq!((o.u(), o.v()), (v(35, 35), v(-35, 35)));
        o
    }
    fn flat() -> Obb {
        Obb::new(v(30, 20), v(1, 0)).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        // 50 units apart along n1: face to face.
        check(&obb(), v(0, 0), &obb(), v(40, -30), Touching);
        check(&obb(), v(0, 0), &obb(), v(41, -30), Apart);
        // The diamond's top corner (0, -70) on the flat box's bottom side.
        check(&diamond(), v(0, 0), &flat(), v(0, -90), Touching);
        check(&diamond(), v(0, 0), &flat(), v(0, -91), Apart);
    }

    #[test]
    fn overlapping() {
        // 45 units apart along n1: 5 deep, (-4, 3).
        check(&obb(), v(0, 0), &obb(), v(36, -27), Overlapping(v(-4, 3)));
        // The diamond's top corner 30 into the flat box: down 30.
        check(
            &diamond(),
            v(0, 0),
            &flat(),
            v(0, -60),
            Overlapping(v(0, 30)),
        );
        // The flat box's corner through the diamond's face (35, -35):
        // 700 / 2450 of (-35, 35) = (-10, 10); then 665 / 2450 = (-9.5, 9.5),
        // rounded away.
        check(
            &diamond(),
            v(0, 0),
            &flat(),
            v(50, -50),
            Overlapping(v(-10, 10)),
        );
        check(
            &diamond(),
            v(0, 0),
            &flat(),
            v(50, -51),
            Overlapping(v(-10, 10)),
        );
        check(
            &flat(),
            v(50, -51),
            &diamond(),
            v(0, 0),
            Overlapping(v(10, -10)),
        );
    }

    #[test]
    fn centred_boxes_go_up_both_ways() {
        // n1 (50 deep) beats n2 (100); n1 = (40, -30) points up: (40, -30).
        assert_eq!(
            contact(&obb(), v(3, 3), &obb(), v(3, 3)),
            Overlapping(v(40, -30))
        );
        // Diamond and flat box: the diamond's two axes tie at 4200 / 49.5 =
        // 84.9 (flat box's: 90 and 100); the (1, 1) line wins, pushed up:
        // (-35, -35) * 4200 / 2450 = (-60, -60), whichever comes first.
        assert_eq!(
            contact(&diamond(), v(0, 0), &flat(), v(0, 0)),
            Overlapping(v(-60, -60))
        );
        assert_eq!(
            contact(&flat(), v(0, 0), &diamond(), v(0, 0)),
            Overlapping(v(-60, -60))
        );
    }
}
