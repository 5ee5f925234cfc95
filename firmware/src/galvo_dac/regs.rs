//! The register layer of the galvo DAC stream (RM0090): TIM8 as the sample
//! clock, DAC1 in dual-channel mode triggered by TIM8's TRGO, DMA1 stream
//! 5 channel 7 feeding DHR12RD, DMA2 stream 1 channel 7 (TIM8_UP) feeding
//! GPIOB's BSRR. embassy-stm32 0.6 has no ring-buffered DAC, and its DMA
//! ring buffers own their memory exclusively and start one stream each;
//! the galvo needs two streams started by one timer, buffers the laser
//! gate's hook may darken from any context, and the ring bookkeeping of
//! `galvo-dma`. So this module drives the registers directly, through
//! `embassy_stm32::pac`; nothing else touches these peripherals (the board
//! takes their `Peri` tokens).

use embassy_stm32::pac;
use embassy_stm32::pac::dma::vals::{Dir, Dmdis, Pl, Size};
use galvo_dma::timing::TimerSetting;

/// DMA1 stream of DAC1 channel 1's request (channel 7).
const DAC_STREAM: usize = 5;
/// DMA2 stream of TIM8_UP's request (channel 7).
const LASER_STREAM: usize = 1;
/// Request channel of both streams.
pub const REQUEST_CHANNEL: u8 = 7;
/// DAC trigger selection: TIM8 TRGO.
const TSEL_TIM8_TRGO: u8 = 0b001;

/// Address of DAC1's dual 12-bit right-aligned holding register.
fn dhr12rd_address() -> u32 {
    pac::DAC1.dhr12rd().as_ptr() as u32
}

/// Address of GPIOB's bit set/reset register (the laser pin's port).
fn gpiob_bsrr_address() -> u32 {
    pac::GPIOB.bsrr().as_ptr() as u32
}

/// Boot: TIM8 stopped with TRGO on update, DAC1 both channels enabled on
/// TIM8's trigger without DMA, outputting `word` (a DHR12RD word).
pub fn init(word: u32) {
    let tim = pac::TIM8;
    tim.cr1().write(|w| w.set_cen(false));
    tim.dier().write(|_| {});
    tim.cr2()
        .write(|w| w.set_mms(pac::timer::vals::Mms::UPDATE));
    pac::DAC1.cr().write(|w| {
        for ch in 0..2 {
            w.set_tsel(ch, TSEL_TIM8_TRGO);
            w.set_ten(ch, true);
            w.set_en(ch, true);
        }
    });
    output_now(word);
}

/// Moves `word` to the DAC outputs at once: loads the holding register and
/// generates one update event by software (TRGO triggers the DAC). Only
/// while the streams are stopped (no DMA request is enabled).
fn output_now(word: u32) {
    pac::DAC1
        .dhr12rd()
        .write_value(pac::dac::regs::Dhr12rd(word));
    pac::TIM8.egr().write(|w| w.set_ug(true));
    pac::TIM8.sr().write(|_| {});
}

/// One stream: memory (`len` words from `memory`) to the peripheral
/// register at `peripheral`, circular, 32-bit, direct mode, very high
/// priority; half and complete interrupts when `interrupts`.
fn configure(
    dma: pac::dma::Dma,
    stream: usize,
    peripheral: u32,
    memory: u32,
    len: u16,
    interrupts: bool,
) {
    let st = dma.st(stream);
    st.cr().modify(|w| w.set_en(false));
    while st.cr().read().en() {}
    // Every flag of the stream must be clear before it is enabled.
    dma.ifcr(stream / 4).write(|w| {
        let n = stream % 4;
        w.set_feif(n, true);
        w.set_dmeif(n, true);
        w.set_teif(n, true);
        w.set_htif(n, true);
        w.set_tcif(n, true);
    });
    st.par().write_value(peripheral);
    st.m0ar().write_value(memory);
    st.ndtr().write(|w| w.set_ndt(len));
    st.fcr().write(|w| w.set_dmdis(Dmdis::ENABLED));
    st.cr().write(|w| {
        w.set_chsel(REQUEST_CHANNEL);
        w.set_dir(Dir::MEMORY_TO_PERIPHERAL);
        w.set_circ(true);
        w.set_minc(true);
        w.set_psize(Size::BITS32);
        w.set_msize(Size::BITS32);
        w.set_pl(Pl::VERY_HIGH);
        w.set_teie(interrupts);
        w.set_dmeie(interrupts);
        w.set_htie(interrupts);
        w.set_tcie(interrupts);
        w.set_en(true);
    });
}

/// Starts both streams in lockstep: the DAC outputs `first` (the ring's
/// first DAC word, so the DAC's one-update delay repeats it once), the
/// timer gets `timer`; both DMA streams wait for the same update events,
/// which begin when the timer starts.
pub fn start(dac_words: u32, laser_words: u32, len: u16, first: u32, timer: TimerSetting) {
    stop();
    let tim = pac::TIM8;
    tim.psc().write_value(timer.prescaler);
    tim.arr().write(|w| w.set_arr(timer.reload));
    tim.cnt().write(|w| w.set_cnt(0));
    // Loads PSC/ARR and latches `first` into the DAC (no request enabled).
    output_now(first);
    configure(
        pac::DMA1,
        DAC_STREAM,
        dhr12rd_address(),
        dac_words,
        len,
        true,
    );
    configure(
        pac::DMA2,
        LASER_STREAM,
        gpiob_bsrr_address(),
        laser_words,
        len,
        false,
    );
    pac::DAC1.cr().modify(|w| w.set_dmaen(0, true));
    tim.dier().write(|w| w.set_ude(true));
    tim.cr1().write(|w| {
        w.set_arpe(true);
        w.set_cen(true);
    });
}

/// Stops the sample clock (no more DAC or laser transfers), then both
/// streams. The DAC keeps its last output.
pub fn stop() {
    pac::TIM8.cr1().modify(|w| w.set_cen(false));
    pac::TIM8.dier().write(|_| {});
    pac::DMA1.st(DAC_STREAM).cr().modify(|w| w.set_en(false));
    pac::DMA2.st(LASER_STREAM).cr().modify(|w| w.set_en(false));
    pac::DAC1.cr().modify(|w| w.set_dmaen(0, false));
}

/// Applies `timer` from the next update event on (PSC and ARR are both
/// preloaded).
pub fn set_timer(timer: TimerSetting) {
    pac::TIM8.psc().write_value(timer.prescaler);
    pac::TIM8.arr().write(|w| w.set_arr(timer.reload));
}

/// The DAC stream's remaining transfers (NDTR).
pub fn dac_ndtr() -> u32 {
    u32::from(pac::DMA1.st(DAC_STREAM).ndtr().read().ndt())
}

/// The laser stream's remaining transfers (NDTR).
pub fn laser_ndtr() -> u32 {
    u32::from(pac::DMA2.st(LASER_STREAM).ndtr().read().ndt())
}

/// What the DAC stream's interrupt found (its flags cleared).
pub struct StreamEvents {
    /// Half boundaries crossed (half transfer and transfer complete).
    pub boundaries: u32,
    /// A transfer or direct-mode error on either stream, or a DAC DMA
    /// underrun (a trigger before the previous request was served): the
    /// streams are no longer trustworthy.
    pub error: Option<&'static str>,
}

/// Reads and clears the DAC stream's flags, the laser stream's error
/// flags and the DAC's DMA underrun flag.
pub fn take_events() -> StreamEvents {
    let (dac_reg, dac_n) = (DAC_STREAM / 4, DAC_STREAM % 4);
    let flags = pac::DMA1.isr(dac_reg).read();
    pac::DMA1.ifcr(dac_reg).write(|w| {
        w.set_htif(dac_n, true);
        w.set_tcif(dac_n, true);
        w.set_teif(dac_n, true);
        w.set_dmeif(dac_n, true);
        w.set_feif(dac_n, true);
    });
    let (laser_reg, laser_n) = (LASER_STREAM / 4, LASER_STREAM % 4);
    let laser = pac::DMA2.isr(laser_reg).read();
    let laser_error = laser.teif(laser_n) || laser.dmeif(laser_n);
    if laser_error {
        pac::DMA2.ifcr(laser_reg).write(|w| {
            w.set_teif(laser_n, true);
            w.set_dmeif(laser_n, true);
        });
    }
    let dac_underrun = pac::DAC1.sr().read().dmaudr(0);
    if dac_underrun {
        pac::DAC1.sr().write(|w| w.set_dmaudr(0, true));
    }
    let error = if flags.teif(dac_n) || flags.dmeif(dac_n) {
        Some("DAC stream transfer error")
    } else if laser_error {
        Some("laser stream transfer error")
    } else if dac_underrun {
        Some("DAC DMA underrun")
    } else {
        None
    };
    StreamEvents {
        boundaries: u32::from(flags.htif(dac_n)) + u32::from(flags.tcif(dac_n)),
        error,
    }
}
