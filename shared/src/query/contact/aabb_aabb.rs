//! Contact between an axis-aligned box and an axis-aligned box.

use super::{Contact, Proximity};
use crate::shape::Aabb;
use glam::IVec2;

/// The SAT answer for two unit axes, specialised: no projections, no
/// products. Ties pick the x axis; a centred box is pushed left or up, the
/// same choices the general kernel makes.
impl Contact<Aabb> for Aabb {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Aabb, other_pos: IVec2) -> Proximity {
        let d = other_pos.as_i64vec2() - pos.as_i64vec2();
        let reach = self.half().as_i64vec2() + other.half().as_i64vec2();
        let ox = reach.x - d.x.abs();
        let oy = reach.y - d.y.abs();
        if ox < 0 || oy < 0 {
            return Proximity::Apart;
        }
        if ox == 0 || oy == 0 {
            return Proximity::Touching;
        }
        let mtv = if ox <= oy {
            IVec2::new(if d.x >= 0 { -ox } else { ox } as i32, 0)
        } else {
            IVec2::new(0, if d.y >= 0 { -oy } else { oy } as i32)
        };
        Proximity::Overlapping(mtv)
    }
}

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::Aabb;

    use crate::query::contact::sat;
    use proptest::prelude::*;

    fn b(x: i32, y: i32) -> Aabb {
        Aabb::new(v(x, y)).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let (a, s) = (b(50, 30), b(20, 20));
        for p in [v(70, 0), v(70, 50), v(-70, -50), v(0, 50), v(-3, -50)] {
            check(&a, v(0, 0), &s, p, Touching);
        }
        for p in [v(71, 0), v(0, 51), v(71, 51), v(-71, -50)] {
            check(&a, v(0, 0), &s, p, Apart);
        }
    }

    #[test]
    fn overlapping() {
        let (a, s) = (b(50, 30), b(20, 20));
        // Reach (70, 50): overlaps 10 and 10 tie, x wins.
        check(&a, v(0, 0), &s, v(60, 40), Overlapping(v(-10, 0)));
        check(&a, v(0, 0), &s, v(65, 40), Overlapping(v(-5, 0)));
        check(&a, v(0, 0), &s, v(60, 45), Overlapping(v(0, -5)));
        check(&a, v(0, 0), &s, v(0, 10), Overlapping(v(0, -40)));
        check(&a, v(0, 0), &s, v(-1, -49), Overlapping(v(0, 1)));
    }

    #[test]
    fn centred_boxes_go_up_or_left_both_ways() {
        let (a, s) = (b(50, 30), b(20, 20));
        assert_eq!(contact(&a, v(0, 0), &s, v(0, 0)), Overlapping(v(0, -50)));
        assert_eq!(contact(&s, v(0, 0), &a, v(0, 0)), Overlapping(v(0, -50)));
        // Equal squares: x and y tie, x wins, pushed left.
        assert_eq!(
            contact(&b(10, 10), v(7, 7), &b(10, 10), v(7, 7)),
            Overlapping(v(-20, 0))
        );
        // Centred on x only, with x shallower.
        assert_eq!(
            contact(&b(10, 40), v(0, 0), &b(10, 40), v(0, 5)),
            Overlapping(v(-20, 0))
        );
        assert_eq!(
            contact(&b(10, 40), v(0, 5), &b(10, 40), v(0, 0)),
            Overlapping(v(-20, 0))
        );
    }

    /// The specialised pair is the generic SAT kernel on two boxes: every
    /// small case exhaustively.
    #[test]
    fn specialised_equals_generic_sat_exhaustively() {
        let sizes = [1, 2, 3, 5];
        for ax in sizes {
            for ay in sizes {
                for bx in sizes {
                    for by in sizes {
                        let (a, o) = (b(ax, ay), b(bx, by));
                        for x in -11..=11 {
                            for y in -11..=11 {
                                let p = v(x, y);
                                assert_eq!(
                                    contact(&a, v(0, 0), &o, p),
                                    sat(&a, v(0, 0), &o, p),
                                    "{a:?} {o:?} at {p}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    proptest! {
        /// ...and at every scale and anywhere in the world.
        #[test]
        fn specialised_equals_generic_sat(
            e in 0u32..=26,
            a in (1i32..=1 << 26, 1i32..=1 << 26),
            o in (1i32..=1 << 26, 1i32..=1 << 26),
            d in (-(1i32 << 27)..=1 << 27, -(1i32 << 27)..=1 << 27),
            pa in (-(1i32 << 30)..=1 << 30, -(1i32 << 30)..=1 << 30),
        ) {
            // Scale sizes and offset down together so that every class occurs.
            let k = |c: i32| (c >> (26 - e)).max(1);
            let a = b(k(a.0), k(a.1));
            let o = b(k(o.0), k(o.1));
            let pa = v(pa.0, pa.1);
            let pb = pa + v(d.0 >> (26 - e), d.1 >> (26 - e));
            prop_assert_eq!(contact(&a, pa, &o, pb), sat(&a, pa, &o, pb));
            prop_assert_eq!(contact(&o, pb, &a, pa), sat(&o, pb, &a, pa));
        }
    }
}
