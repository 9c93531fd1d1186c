//! Storage order of the monomers: along a space-filling curve (Morton / Z order of their grid
//! cell), so that monomers that touch are stored close together and a pass over contacts
//! reads memory that is already in the caches. RBD samples come in deposition order, in which
//! a monomer's neighbours lie anywhere in the array.

use glam::DVec3;

/// Spreads the low 21 bits of `v` to every third bit (bit k to bit 3k).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Morton code of integer cell coordinates (each below 2²¹).
pub fn morton_code(cell: [u64; 3]) -> u64 {
    spread(cell[0]) | spread(cell[1]) << 1 | spread(cell[2]) << 2
}

/// The order in which to store monomers at `position`: by the Morton code of their cell of edge
/// `cell` (cells counted from the lowest corner of the positions), ties by current index. A
/// function of the positions alone, so every backend given the same sample gets the same order.
pub fn space_filling_order(position: &[DVec3], cell: f64) -> Vec<u32> {
    let low = position
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, p| a.min(*p));
    let limit = ((1u64 << 21) - 1) as f64;
    let mut keyed: Vec<(u64, u32)> = position
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let c = ((*p - low) / cell).floor();
            let coord = |v: f64| v.clamp(0.0, limit) as u64;
            (morton_code([coord(c.x), coord(c.y), coord(c.z)]), i as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_interleave_x_y_z_bits() {
        // x = 0b11, y = 0b01, z = 0b10: bits x0 y0 z0 x1 y1 z1 = 1 1 0 1 0 1 → 0b101011.
        assert_eq!(morton_code([0b11, 0b01, 0b10]), 0b101011);
        assert_eq!(morton_code([1 << 20, 0, 0]), 1 << 60);
        assert_eq!(morton_code([0, 0, 1 << 20]), 1 << 62);
        assert_eq!(morton_code([(1 << 21) - 1; 3]), (1 << 63) - 1);
    }

    #[test]
    fn the_order_is_a_permutation_visiting_cells_in_z_order() {
        // Eight points, one per cell of a 2×2×2 block, listed in reverse Z order.
        let mut points = Vec::new();
        for code in (0..8u64).rev() {
            let (x, y, z) = (code & 1, code >> 1 & 1, code >> 2 & 1);
            points.push(DVec3::new(x as f64, y as f64, z as f64) + 0.5);
        }
        let order = space_filling_order(&points, 1.0);
        assert_eq!(order, vec![7, 6, 5, 4, 3, 2, 1, 0]);
        // Two monomers in one cell keep their index order.
        let order = space_filling_order(&[DVec3::splat(0.2), DVec3::splat(0.1)], 1.0);
        assert_eq!(order, vec![0, 1]);
    }
}
