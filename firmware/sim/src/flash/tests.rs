use super::*;
use embassy_futures::block_on;

type Flash = SimFlash<256>;

#[test]
fn programming_only_clears_bits_and_erase_sets_them() {
    let mut f = Flash::erased(0x400, 2);
    block_on(f.write(0x404, &[0x0F, 0xF0, 0x00, 0xFF])).unwrap();
    block_on(f.write(0x404, &[0xF3, 0x3F, 0xFF, 0x00])).unwrap();
    let mut word = [0u8; 4];
    block_on(f.read(0x404, &mut word)).unwrap();
    assert_eq!(word, [0x03, 0x30, 0x00, 0x00]);
    assert_eq!(f.stats().rewrites, 1);
    block_on(f.erase(0x400, 0x500)).unwrap();
    block_on(f.read(0x404, &mut word)).unwrap();
    assert_eq!(word, [0xFF; 4]);
    assert_eq!(f.ops(), 3);
}

#[test]
fn misaligned_or_outside_accesses_are_refused() {
    let mut f = Flash::erased(0x400, 2);
    assert_eq!(
        block_on(f.write(0x402, &[0; 4])),
        Err(SimFlashError::NotAligned)
    );
    assert_eq!(
        block_on(f.write(0x400, &[0; 3])),
        Err(SimFlashError::NotAligned)
    );
    assert_eq!(
        block_on(f.erase(0x480, 0x500)),
        Err(SimFlashError::NotAligned)
    );
    assert_eq!(
        block_on(f.read(0x3FF, &mut [0; 1])),
        Err(SimFlashError::OutOfBounds)
    );
    assert_eq!(
        block_on(f.write(0x600, &[0; 4])),
        Err(SimFlashError::OutOfBounds)
    );
    assert_eq!(f.ops(), 0, "a refused access is no operation");
}

#[test]
fn a_power_cut_tears_the_operation_and_stops_the_flash() {
    let words = [0u8; 12];
    let expect = |tear: Tear| -> [u8; 4] {
        let mut f = Flash::erased(0, 1).with_power_cut(Some(PowerCut { at_op: 1, tear }));
        assert_eq!(block_on(f.write(0, &words)), Err(SimFlashError::PowerLost));
        assert!(!f.powered());
        assert_eq!(f.ops(), 2);
        assert_eq!(&f.image()[..4], &[0; 4], "op 0 completed");
        assert_eq!(&f.image()[8..12], &[0xFF; 4], "op 2 never started");
        assert_eq!(
            block_on(f.read(0, &mut [0; 4])),
            Err(SimFlashError::PowerLost)
        );
        f.image()[4..8].try_into().unwrap()
    };
    assert_eq!(expect(Tear::NotStarted), [0xFF; 4]);
    assert_eq!(expect(Tear::FirstHalf), [0, 0, 0xFF, 0xFF]);
    let scattered = u32::from_le_bytes(expect(Tear::EveryOther));
    assert_eq!(scattered.count_ones(), 16, "{scattered:#x}");

    let mut f = Flash::from_image(0, vec![0u8; 256]).with_power_cut(Some(PowerCut {
        at_op: 0,
        tear: Tear::FirstHalf,
    }));
    assert_eq!(block_on(f.erase(0, 256)), Err(SimFlashError::PowerLost));
    assert!(f.image()[..128].iter().all(|b| *b == 0xFF));
    assert!(f.image()[128..].iter().all(|b| *b == 0));
    let mut f = Flash::from_image(0, vec![0u8; 256]).with_power_cut(Some(PowerCut {
        at_op: 0,
        tear: Tear::EveryOther,
    }));
    assert!(block_on(f.erase(0, 256)).is_err());
    assert_eq!(f.image().iter().filter(|b| **b == 0xFF).count(), 128);
}
