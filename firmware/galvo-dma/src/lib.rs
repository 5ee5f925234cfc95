//! The pure part of the STM32F4 galvo DAC stream: everything the firmware's
//! register layer (`firmware/src/galvo_dac`) decides from numbers, kept
//! here so it runs (and is tested) on the host.
//!
//! The hardware it models (RM0090): TIM8's update event triggers DAC1 in
//! dual-channel mode; each trigger moves the DAC's holding register
//! (DHR12RD, both 12-bit codes in one word) to its outputs and then raises
//! a DMA request (DMA1 stream 5, channel 7) that loads the *next* word from
//! a circular buffer. The same update event raises TIM8_UP's request on
//! DMA2 stream 1 (channel 7), which copies one word from a second circular
//! buffer to GPIOB's BSRR (the laser pin). Both buffers hold two halves of
//! `half_len` samples; the loop refills the half the DMA is not reading.
//!
//! * [`words`]: a sample's DHR12RD word and its laser BSRR word, and the
//!   half packing that keeps the laser edges on the DAC's sample
//!   boundaries (the DAC outputs each word one update after the DMA read
//!   it; a BSRR write acts at once).
//! * [`ring`]: the ring layout, the half the DMA reads from its NDTR
//!   counter, whether the next half is free or already late (underrun),
//!   the interrupt's underrun check, lockstep of the two streams, and the
//!   refill's cursor (prime both halves, claim, commit, check).
//! * [`timing`]: TIM8 prescaler/reload for a sample period, and the worst
//!   refill time from cycle-counter readings.
#![no_std]

#[cfg(test)]
extern crate std;

pub mod ring;
pub mod timing;
pub mod words;
