//! # tss-reel firmware for the NUCLEO-G474RE board (STM32G474RE, Cortex-M4F)
//!
//! The reel-mechanism MCU on a real motor-control board: `cargo fw-board` builds it (flight
//! profile), `probe-rs run --chip STM32G474RETx` flashes it and prints its defmt log over RTT
//! (the runner of `.cargo/config.toml` for this target when `CARGO_TARGET_…_RUNNER` is set to it,
//! see docs/porting.md). Nothing runs it in CI: the test command builds it, lints it and checks
//! its size budget. This file is the board code, and only that: it builds the peripherals and
//! hands them to the board-independent parts through their traits:
//!
//! | what | peripheral (NUCLEO-G474RE pin, Arduino name) | trait → user |
//! |---|---|---|
//! | motor PWM, 20 kHz | TIM1 CH1 (PA8, D7) | `SetDutyCycle` → [`HalReelDrive`] |
//! | direction / brake / enable | PA10 (D2) / PB5 (D4) / PB4 (D5), push-pull | `OutputPin` → [`HalReelDrive`] |
//! | drum encoder, quadrature ×4 | TIM2 encoder mode, 32-bit (PA0 A0, PA1 A1) | [`QuadratureEncoder`] ([`Tim2Encoder`]) |
//! | tension load cell amplifier | ADC1 IN15 (PB0, A3) | [`LoadCell`] ([`AdcLoadCell`]) |
//! | on-board computer link, 115 200 Bd 8N1 | USART2, TX PA2 / RX PA3 (AF7): the ST-LINK's virtual COM port | [`BytePort`] ([`ObcPort`]) → [`PacketPort`] |
//! | log | defmt over RTT (SWD, the ST-LINK) | — |
//!
//! ## Two rates
//! - **Inner**, [`INNER_RATE_HZ`] (1 kHz; any rate ≥ 100 Hz that SysTick can make on the
//!   16 MHz clock, checked at compile time): the SysTick exception reads the encoder and the
//!   load cell, steps [`tss_reel::reel_drive::SpeedLoop`] and sets the motor outputs
//!   ([`HalReelDrive::tick`]). It preempts the outer step, so a long outer step never delays it.
//!   An inner step still running when the next SysTick is due is an inner overrun: counted
//!   (the pending bit is seen at the handler's end) and logged at the outer rate.
//! - **Outer**, [`OUTER_PERIOD_TICKS`] inner ticks (1 s, the law's period): the main loop, in
//!   thread mode, wakes on every SysTick (WFI), and when a law period has gone by it runs one
//!   [`control_cycle`] of the flight controller (`Controller<f32>`, `Config::flight`: on the
//!   estimator) and hands its rate command (Eq. 29–30) to the speed loop in a critical section. Law
//!   periods that went by without a step are outer overruns: counted and logged.
//!
//! ## Where the outer law's sensors come from
//! The board has the drum's encoder and the tension load cell, and nothing else. The outer law
//! also needs the tether length, the in-plane libration α and its rate, and the orbit rate,
//! which the spacecraft's other sensors provide (a serial link later, as the QEMU build's PIL
//! link does). Until then they come from **the recorded mission**
//! ([`tss_reel::recordings::replay`]: the first 720 s of `scenarios/paper.toml` as the reel
//! MCU senses it, with its injected 50 s dropout, and the paper's circular orbit rate), read
//! through the QEMU firmware's sensor type, `tss_reel::recordings::sensors::Replay`. The drum on
//! the bench therefore runs the paper's reel-rate profile against whatever load it has; the log
//! shows, once a law period, the commanded rate, the drum's measured speed and paid-out length
//! (from the encoder), and the tension (from the load cell). When the replay ends the drive is
//! put in safe hold (brake engaged, motor off) and the inner loop keeps holding it.
//!
//! ## The on-board computer's link (PUS over USART2)
//! The unit's telecommands and telemetry (`tss_reel::pus`, docs/interface.md) travel on USART2
//! as the processor-in-the-loop link frames them: one space packet per `Packet` frame (COBS,
//! `0x00` delimiter, CRC-32). The board only moves bytes; reassembly, the hand-over to
//! [`Services`] and the telemetry's framing are the library's [`PacketPort`], tested on the
//! host (`tests/pus_port.rs`). docs/porting.md says how to talk to it from a PC.
//! - **Rate**: [`LINE_RATE_BAUD`] (115 200 Bd 8N1, 11 520 bytes/s): a worst period's telemetry
//!   (1 627 B, `tests/pus_port.rs`) takes 141 ms of the 1 s period. USART2 divides its 16 MHz
//!   PCLK1 by 138: 115 942 Bd, 0.6 % fast, inside the ±2 % an 8N1 receiver tolerates.
//! - **Receive, by interrupt**: the line brings 11.5 bytes per millisecond, more than the
//!   receive FIFO (8 bytes) holds between two 1 kHz SysTicks, so the inner tick cannot poll
//!   it. The USART2 interrupt (receive FIFO not empty) moves every byte, or the line error in
//!   its place, into a [`RX_QUEUE_BYTES`] queue. A byte is lost only if that interrupt waits
//!   9 byte times (780 µs): the longest it waits is one inner step (SysTick, same priority) or
//!   one of the main loop's short critical sections (a byte, or [`TX_CHUNK_BYTES`] bytes). The
//!   queue holds 89 ms of the line for the main loop, which drains it at every wake; a full
//!   queue or a receiver overrun is an `Overrun` in the stream, a framing, noise or parity
//!   error a `Framing`: the port counts them and drops the frame they fall in.
//! - **Hand-over**: at the law period's boundary the telecommands received go to
//!   [`Services`], then the controller steps, then its telemetry (verification, events,
//!   housekeeping) is queued, as the host's unit does it.
//! - **Transmit, by interrupt**: telemetry frames go whole into a [`TX_QUEUE_BYTES`] queue (or
//!   are dropped and counted); the USART2 interrupt (transmit FIFO not full) feeds the line.
//!
//! When the replay ends the controller stops stepping: telecommands are still verified and
//! housekeeping still sent each period, but a mode command is never completed. The link's
//! counts are logged when a loss grows; the controller's events go to the on-board computer
//! (TM\[5,x\]), not to the log.
//!
//! ## Faults
//! A panic (panic-probe logs it) or any fault ends in [`HardFault`], which logs and resets the
//! MCU: out of reset every pin is an input, so the driver's enable falls (pulled down on the
//! driver board) and the spring brake engages. Unhandled interrupts do the same.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![deny(unsafe_code)]
#![warn(missing_docs)]

#[cfg(not(target_os = "none"))]
compile_error!(
    "the NUCLEO-G474RE firmware runs on the board's STM32G474RE: build it for \
     thumbv7em-none-eabihf (`cargo fw-board`)"
);

/// The board itself (bare metal only).
#[cfg(target_os = "none")]
mod board {
    use core::cell::RefCell;
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::interrupt::Mutex;
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m::peripheral::{NVIC, SCB};
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use defmt_rtt as _;
    use heapless::Deque;
    use panic_probe as _;

    use stm32g4xx_hal::adc::config::{AdcConfig, SampleTime};
    use stm32g4xx_hal::adc::{Adc, AdcClaim, AdcCommonExt, Configured};
    use stm32g4xx_hal::gpio::{Analog, Output, PushPull, AF7, PA10, PA2, PA3, PB0, PB4, PB5};
    use stm32g4xx_hal::hal_02::serial::{Read as _, Write as _};
    use stm32g4xx_hal::nb;
    use stm32g4xx_hal::prelude::*;
    use stm32g4xx_hal::pwm::{ActiveHigh, ComplementaryDisabled, Pwm, C1};
    use stm32g4xx_hal::pwr::PwrExt;
    use stm32g4xx_hal::rcc::{Config as ClockConfig, Enable, Reset};
    use stm32g4xx_hal::serial::{self, FullConfig, NoDMA};
    use stm32g4xx_hal::stm32::{self, interrupt, Interrupt, ADC1, TIM1, TIM2, USART2};
    use stm32g4xx_hal::time::RateExtU32;

    use tss_reel::controller::{Config, Controller};
    use tss_reel::hal::{control_cycle, BytePort, Devices, ErrorKind, ErrorType, ReelDrive};
    use tss_reel::pus::port::{PacketPort, LINE_RATE_BAUD, RX_QUEUE_BYTES, TX_QUEUE_BYTES};
    use tss_reel::pus::Services;
    use tss_reel::recordings::replay::{
        DROPOUT_FROM_TICK, DROPOUT_UNTIL_TICK, ORBIT_RATE_RADPS, PERIOD_S, SAMPLES,
    };
    // The outer law's sensors that the board does not have: the recorded mission (see the
    // crate docs), with its injected dropout, as the QEMU firmware's replay.
    use tss_reel::recordings::sensors::Replay;
    use tss_reel::reel_drive::hal::{HalReelDrive, LoadCell, MotorPins, QuadratureEncoder};
    use tss_reel::reel_drive::{DriveConfig, DriveFaults, RateCommand, SpeedLoop};

    /// The core clock: the internal 16 MHz oscillator (HSI16), no PLL. Enough for a 1 kHz
    /// inner loop of ~200 instructions plus one ADC conversion; raising it (PLL to 170 MHz) is
    /// a change of [`clock_config`] and this constant only.
    pub const CORE_CLOCK_HZ: u32 = 16_000_000;

    /// Inner (speed-loop) rate, Hz: the SysTick rate. Configurable: at least 100 Hz (the speed
    /// loop's minimum, `reel_drive::config::MIN_INNER_RATE_HZ`), a divisor of the core clock
    /// that fits SysTick's 24-bit counter.
    pub const INNER_RATE_HZ: u32 = 1_000;

    /// The outer law's period in inner ticks: 1 s, the recording's period.
    pub const OUTER_PERIOD_TICKS: u32 = INNER_RATE_HZ;

    /// SysTick reload for [`INNER_RATE_HZ`] on the core clock.
    const SYST_RELOAD: u32 = CORE_CLOCK_HZ / INNER_RATE_HZ - 1;

    const _: () = assert!(INNER_RATE_HZ >= 100);
    const _: () = assert!(CORE_CLOCK_HZ.is_multiple_of(INNER_RATE_HZ));
    const _: () = assert!(SYST_RELOAD >= 1 && SYST_RELOAD <= 0x00FF_FFFF);
    const _: () = assert!(PERIOD_S == 1.0);

    /// Motor PWM frequency: above hearing, within the driver's range.
    const PWM_FREQUENCY_HZ: u32 = 20_000;

    /// Log the drive's state every this many law periods (and at every controller event).
    const LOG_EVERY_PERIODS: u32 = 10;

    /// The motor PWM: TIM1 channel 1 on PA8.
    type MotorPwm = Pwm<TIM1, C1, ComplementaryDisabled, ActiveHigh, ActiveHigh>;

    /// The reel drive of this board: the speed loop over its peripherals.
    type BoardDrive = HalReelDrive<
        Tim2Encoder,
        AdcLoadCell,
        MotorPwm,
        PA10<Output<PushPull>>,
        PB5<Output<PushPull>>,
        PB4<Output<PushPull>>,
    >;

    /// What the SysTick handler owns: the drive, and the command waiting for it.
    struct Inner {
        drive: BoardDrive,
        /// The law's latest command, taken at the next inner tick.
        pending: Option<RateCommand>,
        /// The faults of the inner ticks since the outer loop last took them (their union),
        /// for the law's next step ([`control_cycle`]).
        period_faults: DriveFaults,
    }

    /// Shared between the SysTick handler (inner loop) and the main loop (outer loop): every
    /// access is in a critical section, short (a copy in or out).
    static INNER: Mutex<RefCell<Option<Inner>>> = Mutex::new(RefCell::new(None));

    /// Inner ticks since start (SysTick handler), wrapping after 49 days at 1 kHz; every use
    /// takes differences.
    static INNER_TICKS: AtomicU32 = AtomicU32::new(0);

    /// Inner steps that had not finished when the next SysTick was due.
    static INNER_OVERRUNS: AtomicU32 = AtomicU32::new(0);

    // Log lines carry the board's time since start, ms.
    defmt::timestamp!(
        "{=u64:tms}",
        u64::from(INNER_TICKS.load(Ordering::Relaxed)) * 1_000 / u64::from(INNER_RATE_HZ)
    );

    /// The drum encoder: TIM2 (32-bit) in encoder mode 3 (counts on both edges of both
    /// channels: 4 counts per encoder line), free-running over its whole range.
    pub struct Tim2Encoder {
        tim: TIM2,
    }

    impl Tim2Encoder {
        /// Puts TIM2 in encoder mode on PA0 (TI1) and PA1 (TI2), input filter N = 8, and starts it.
        fn start(tim: TIM2, rcc: &mut stm32g4xx_hal::rcc::Rcc) -> Self {
            TIM2::enable(rcc);
            TIM2::reset(rcc);
            tim.ccmr1_input().write(|w| {
                w.cc1s().ti1();
                w.cc2s().ti2();
                w.ic1f().fck_int_n8();
                w.ic2f().fck_int_n8()
            });
            // Both inputs non-inverted (CCER reset value).
            tim.arr().write(|w| w.arr().set(u32::MAX));
            // SMS = 0b011, encoder mode 3 (RM0440 §29.3.22). The PAC marks SMS as unchecked
            // because some of its values need other bits set; 0b011 needs none.
            #[allow(unsafe_code)]
            // SAFETY: writes a valid SMS value to a timer this function owns.
            tim.smcr().write(|w| unsafe { w.sms().bits(0b011) });
            tim.cr1().write(|w| w.cen().set_bit());
            Self { tim }
        }
    }

    impl ErrorType for Tim2Encoder {
        type Error = ErrorKind;
    }

    impl QuadratureEncoder for Tim2Encoder {
        fn read_count(&mut self) -> Result<u32, ErrorKind> {
            Ok(self.tim.cnt().read().cnt().bits())
        }
    }

    /// The load cell's amplifier as ADC1 sees it: a voltage linear in the tension.
    ///
    /// The figures are the bench amplifier's specification (0 N at 0.3 V, 100 N at 3.0 V: a
    /// live zero, so a cut wire or a dead amplifier reads 0 V, below the zero, and is not a
    /// tension); calibrate them on the bench (docs/porting.md).
    #[derive(Clone, Copy, Debug)]
    pub struct LoadCellScale {
        /// Output at zero tension, mV.
        pub zero_mv: u16,
        /// Output at [`Self::full_scale_n`], mV.
        pub full_scale_mv: u16,
        /// The tension at full scale, N.
        pub full_scale_n: f32,
    }

    /// This board's load cell amplifier (see [`LoadCellScale`]).
    pub const LOAD_CELL: LoadCellScale = LoadCellScale {
        zero_mv: 300,
        full_scale_mv: 3_000,
        full_scale_n: 100.0,
    };

    /// The tension load cell on ADC1 channel 15 (PB0), one blocking conversion per read.
    pub struct AdcLoadCell {
        adc: Adc<ADC1, Configured>,
        pin: PB0<Analog>,
        scale: LoadCellScale,
    }

    impl ErrorType for AdcLoadCell {
        type Error = ErrorKind;
    }

    impl LoadCell for AdcLoadCell {
        /// A reading below half the live zero is a broken sensor (a device fault), never a
        /// tension; the speed loop then treats the tension as missing.
        fn read_tension_n(&mut self) -> Result<f32, ErrorKind> {
            let sample = self.adc.convert(&self.pin, SampleTime::Cycles_47_5);
            let mv = self.adc.sample_to_millivolts(sample);
            let s = self.scale;
            if mv < s.zero_mv / 2 {
                return Err(ErrorKind::Device);
            }
            let span_mv = f32::from(s.full_scale_mv) - f32::from(s.zero_mv);
            Ok((f32::from(mv) - f32::from(s.zero_mv)) * (s.full_scale_n / span_mv))
        }
    }

    /// Bytes the USART2 interrupt moves per call at most, each way: the 8-byte FIFO and the
    /// shift register, twice (a bounded loop; what is left raises the interrupt again).
    const USART_BYTES_PER_INTERRUPT: usize = 18;

    /// Bytes of a telemetry frame the main loop queues per critical section: short enough not
    /// to delay the inner step or the receiver noticeably.
    const TX_CHUNK_BYTES: usize = 16;

    /// USART2, split: the receiver and the transmitter.
    struct Usart2 {
        tx: serial::Tx<USART2, PA2<AF7>, NoDMA>,
        rx: serial::Rx<USART2, PA3<AF7>, NoDMA>,
    }

    /// The line to the on-board computer: USART2 and its two queues. The USART2 interrupt
    /// moves bytes between the hardware and the queues; the main loop reads and fills the
    /// queues ([`ObcPort`]). Every access is in a critical section.
    struct ObcLine {
        /// The USART, once `main` has set it up.
        usart: Option<Usart2>,
        /// Received bytes, or the line error in their place, oldest first.
        received: Deque<Result<u8, ErrorKind>, RX_QUEUE_BYTES>,
        /// Telemetry frames' bytes waiting for the line, oldest first.
        to_send: Deque<u8, TX_QUEUE_BYTES>,
    }

    /// Shared between the USART2 interrupt and the main loop (zero-initialised: `.bss`).
    static OBC_LINE: Mutex<RefCell<ObcLine>> = Mutex::new(RefCell::new(ObcLine {
        usart: None,
        received: Deque::new(),
        to_send: Deque::new(),
    }));

    impl ObcLine {
        /// The interrupt's work: the receive FIFO into [`Self::received`], then
        /// [`Self::to_send`] into the transmit FIFO (its interrupt off once the queue is empty).
        fn move_bytes(&mut self) {
            let Some(usart) = self.usart.as_mut() else {
                return;
            };
            for _ in 0..USART_BYTES_PER_INTERRUPT {
                let item = match usart.rx.read() {
                    Ok(byte) => Ok(byte),
                    Err(nb::Error::WouldBlock) => break,
                    Err(nb::Error::Other(serial::Error::Overrun)) => Err(ErrorKind::Overrun),
                    // Framing, noise, parity: the damaged byte follows in the next read.
                    Err(nb::Error::Other(_)) => Err(ErrorKind::Framing),
                };
                if self.received.push_back(item).is_err() {
                    // The queue is full: this byte is lost, and the newest kept one becomes
                    // the overrun that stands for the loss.
                    if let Some(newest) = self.received.back_mut() {
                        *newest = Err(ErrorKind::Overrun);
                    }
                }
            }
            for _ in 0..USART_BYTES_PER_INTERRUPT {
                let Some(&byte) = self.to_send.front() else {
                    usart.tx.unlisten();
                    break;
                };
                if usart.tx.write(byte).is_err() {
                    break; // FIFO full: the interrupt comes back when it is not
                }
                let _ = self.to_send.pop_front();
            }
        }
    }

    /// The main loop's end of the line to the on-board computer: [`BytePort`] over
    /// [`ObcLine`]'s queues.
    pub struct ObcPort;

    impl ErrorType for ObcPort {
        type Error = ErrorKind;
    }

    impl BytePort for ObcPort {
        fn read_byte(&mut self) -> Result<Option<u8>, ErrorKind> {
            cortex_m::interrupt::free(|cs| {
                // As in `SysTick`: the borrow cannot fail (critical section, one core).
                let mut line = OBC_LINE
                    .borrow(cs)
                    .try_borrow_mut()
                    .map_err(|_| ErrorKind::Other)?;
                line.received.pop_front().transpose()
            })
        }

        fn send(&mut self, bytes: &[u8]) -> Result<(), ErrorKind> {
            // Only the main loop fills the queue and the interrupt only empties it, so room
            // seen here is still there for the chunks below.
            cortex_m::interrupt::free(|cs| {
                let line = OBC_LINE
                    .borrow(cs)
                    .try_borrow()
                    .map_err(|_| ErrorKind::Other)?;
                let room = line.to_send.capacity() - line.to_send.len();
                match line.usart {
                    None => Err(ErrorKind::Other),
                    Some(_) if room < bytes.len() => Err(ErrorKind::Full),
                    Some(_) => Ok(()),
                }
            })?;
            for chunk in bytes.chunks(TX_CHUNK_BYTES) {
                cortex_m::interrupt::free(|cs| {
                    let mut line = OBC_LINE
                        .borrow(cs)
                        .try_borrow_mut()
                        .map_err(|_| ErrorKind::Other)?;
                    let line = &mut *line;
                    for &b in chunk {
                        line.to_send.push_back(b).map_err(|_| ErrorKind::Full)?;
                    }
                    if let Some(usart) = line.usart.as_mut() {
                        usart.tx.listen();
                    }
                    Ok(())
                })?;
            }
            Ok(())
        }
    }

    /// The outer loop's view of the reel: it keeps the law's latest command for the main loop
    /// to hand to the speed loop.
    struct CommandLatch {
        latest: Option<RateCommand>,
    }

    impl ErrorType for CommandLatch {
        type Error = ErrorKind;
    }

    impl ReelDrive for CommandLatch {
        fn command(&mut self, output: &tss_reel::controller::Output<f32>) -> Result<(), ErrorKind> {
            self.latest = Some(RateCommand::from(output));
            Ok(())
        }
    }

    /// The outer loop's state.
    struct Outer {
        controller: Controller<f32>,
        devices: Devices<Replay, Replay, Replay, CommandLatch, Replay>,
        /// The unit's PUS services around the controller.
        services: Services,
        /// The on-board computer's link, reassembled and framed.
        obc: PacketPort,
    }

    impl Outer {
        /// One law period: the telecommands of the period that ended, then read the sensors,
        /// step the controller, queue its telemetry, and return its command.
        ///
        /// Out of line: a symbol `scripts/panic-check` starts from for this board.
        #[inline(never)]
        fn control(&mut self, period: u32, drive: DriveFaults) -> Option<RateCommand> {
            self.obc
                .deliver(&mut ObcPort, &mut self.services, &mut self.controller);
            self.devices.reel.latest = None;
            let cycle = control_cycle(&mut self.controller, period, &mut self.devices, drive);
            self.obc.report(
                &mut ObcPort,
                &mut self.services,
                &mut self.controller,
                cycle.input.as_ref(),
            );
            self.devices.reel.latest
        }

        /// A law period after the replay: no step, but the telecommands are still verified
        /// and the housekeeping (of the last step) still sent.
        ///
        /// Out of line: a symbol `scripts/panic-check` starts from for this board.
        #[inline(never)]
        fn idle(&mut self) {
            self.obc
                .deliver(&mut ObcPort, &mut self.services, &mut self.controller);
            self.obc
                .report(&mut ObcPort, &mut self.services, &mut self.controller, None);
        }

        /// Between law periods: what the on-board computer sent, into the port.
        ///
        /// Out of line: a symbol `scripts/panic-check` starts from for this board.
        #[inline(never)]
        fn listen(&mut self) {
            self.obc.receive(&mut ObcPort);
        }
    }

    /// The clock tree: HSI16 as the system clock, no prescalers (see [`CORE_CLOCK_HZ`]).
    fn clock_config() -> ClockConfig {
        ClockConfig::hsi()
    }

    /// A busy-wait delay on the core clock, for the ADC's start-up (SysTick is the inner
    /// loop's, not a delay).
    struct CycleDelay;

    impl embedded_hal::delay::DelayNs for CycleDelay {
        fn delay_ns(&mut self, ns: u32) {
            let cycles = u64::from(ns) * u64::from(CORE_CLOCK_HZ / 1_000_000) / 1_000 + 1;
            cortex_m::asm::delay(u32::try_from(cycles).unwrap_or(u32::MAX));
        }
    }

    /// Builds the peripherals, hands them to the drive, starts the inner loop, runs the outer.
    #[entry]
    fn main() -> ! {
        defmt::info!(
            "tss-reel {=str} on NUCLEO-G474RE: inner loop {=u32} Hz, law period {=u32} ticks",
            env!("CARGO_PKG_VERSION"),
            INNER_RATE_HZ,
            OUTER_PERIOD_TICKS
        );
        defmt::info!(
            "on-board computer link: USART2 (PA2 TX, PA3 RX), {=u32} Bd 8N1, PUS packets in link frames",
            LINE_RATE_BAUD
        );
        let (Some(dp), Some(mut cp)) = (stm32::Peripherals::take(), cortex_m::Peripherals::take())
        else {
            defmt::panic!("peripherals already taken");
        };

        let pwr = dp.PWR.constrain().freeze();
        let mut rcc = dp.RCC.constrain().freeze(clock_config(), pwr);
        if rcc.clocks.sys_clk.raw() != CORE_CLOCK_HZ {
            defmt::panic!(
                "system clock {=u32} Hz, expected {=u32}",
                rcc.clocks.sys_clk.raw(),
                CORE_CLOCK_HZ
            );
        }
        let gpioa = dp.GPIOA.split(&mut rcc);
        let gpiob = dp.GPIOB.split(&mut rcc);

        // Outputs start low: driver off, brake engaged (HalReelDrive::new confirms it).
        let pins = MotorPins {
            pwm: {
                let mut pwm =
                    dp.TIM1
                        .pwm(gpioa.pa8.into_alternate(), PWM_FREQUENCY_HZ.Hz(), &mut rcc);
                pwm.enable();
                pwm
            },
            direction: gpioa.pa10.into_push_pull_output(),
            brake: gpiob.pb5.into_push_pull_output(),
            enable: gpiob.pb4.into_push_pull_output(),
        };
        let _encoder_pins = (
            gpioa.pa0.into_alternate::<1>(),
            gpioa.pa1.into_alternate::<1>(),
        );
        let encoder = Tim2Encoder::start(dp.TIM2, &mut rcc);
        let adc12 = dp.ADC12_COMMON.claim(Default::default(), &mut rcc);
        let load_cell = AdcLoadCell {
            adc: adc12.claim_and_configure(dp.ADC1, AdcConfig::default(), &mut CycleDelay),
            pin: gpiob.pb0.into_analog(),
            scale: LOAD_CELL,
        };

        // The on-board computer's link: USART2 with its FIFOs, interrupts on a byte received
        // (the transmit interrupt is turned on when there is telemetry to send).
        let usart = match dp.USART2.usart(
            gpioa.pa2.into_alternate(),
            gpioa.pa3.into_alternate(),
            FullConfig::default()
                .baudrate(LINE_RATE_BAUD.bps())
                .fifo_enable(),
            &mut rcc,
        ) {
            Ok(u) => u,
            Err(_) => defmt::panic!("USART2 cannot make {=u32} Bd", LINE_RATE_BAUD),
        };
        let (tx, mut rx) = usart.split();
        rx.listen();
        cortex_m::interrupt::free(|cs| {
            if let Ok(mut line) = OBC_LINE.borrow(cs).try_borrow_mut() {
                line.usart = Some(Usart2 { tx, rx });
            }
        });
        #[allow(unsafe_code)]
        // SAFETY: the USART2 handler shares its data with the main loop only through
        // `OBC_LINE`, in critical sections; unmasking it breaks no critical section.
        unsafe {
            NVIC::unmask(Interrupt::USART2);
        }

        // The speed loop: the reference drive's parameters, this board's rate and counter.
        let mut cfg = DriveConfig::example();
        cfg.inner_rate_hz = INNER_RATE_HZ;
        cfg.geometry.encoder_bits = 32;
        let speed = match SpeedLoop::new(cfg) {
            Ok(s) => s,
            Err(e) => defmt::panic!("drive configuration rejected: {}", e),
        };
        let drive = match HalReelDrive::new(speed, encoder, load_cell, pins) {
            Ok(d) => d,
            Err(e) => defmt::panic!("motor outputs refused the safe state: {}", e),
        };
        cortex_m::interrupt::free(|cs| {
            INNER.borrow(cs).replace(Some(Inner {
                drive,
                pending: None,
                period_faults: DriveFaults::NONE,
            }));
        });

        let controller = match Controller::new(Config::flight()) {
            Ok(c) => c,
            Err(e) => defmt::panic!("controller configuration rejected: {}", e),
        };
        let mut outer = Outer {
            controller,
            devices: Devices {
                length: Replay,
                swing: Replay,
                orbit: Replay,
                reel: CommandLatch { latest: None },
                tension: Replay,
            },
            services: Services::new(),
            obc: PacketPort::new(),
        };

        // The inner loop starts: SysTick on the core clock. It outranks nothing else here; the
        // main loop (thread mode) is what it preempts.
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(SYST_RELOAD);
        cp.SYST.clear_current();
        cp.SYST.enable_interrupt();
        cp.SYST.enable_counter();

        defmt::info!(
            "outer sensors: the recorded mission ({=usize} s of scenarios/paper.toml, dropout at {=u32}..{=u32} s), n = {=f32} rad/s",
            SAMPLES.len(),
            DROPOUT_FROM_TICK,
            DROPOUT_UNTIL_TICK,
            ORBIT_RATE_RADPS
        );
        run(&mut outer)
    }

    /// The outer loop: one law period per [`OUTER_PERIOD_TICKS`] inner ticks, for the length of
    /// the recording, then safe hold for good.
    fn run(outer: &mut Outer) -> ! {
        let start = INNER_TICKS.load(Ordering::Acquire);
        let mut period: u32 = 0;
        let mut outer_overruns: u32 = 0;
        let mut link_losses: u32 = 0;
        loop {
            // Sleep until the law period `period` is due (SysTick wakes us every inner tick,
            // USART2 at every byte), taking in what the on-board computer sends meanwhile.
            let due = period.saturating_mul(OUTER_PERIOD_TICKS);
            let elapsed = loop {
                outer.listen();
                let e = INNER_TICKS.load(Ordering::Acquire).wrapping_sub(start);
                if e >= due {
                    break e;
                }
                cortex_m::asm::wfi();
            };
            // Periods that went by while the previous step ran are skipped, and counted.
            let now_period = elapsed / OUTER_PERIOD_TICKS;
            if now_period > period {
                let skipped = now_period - period;
                outer_overruns = outer_overruns.saturating_add(skipped);
                defmt::warn!("outer overrun: {=u32} law periods skipped", skipped);
                period = now_period;
            }

            // The drive's faults since the last law period reach the law's health.
            let drive_faults = cortex_m::interrupt::free(|cs| {
                let mut inner = INNER.borrow(cs).try_borrow_mut().ok()?;
                inner
                    .as_mut()
                    .map(|i| core::mem::replace(&mut i.period_faults, DriveFaults::NONE))
            })
            .unwrap_or(DriveFaults::NONE);
            let finished = period as usize >= SAMPLES.len();
            let cmd = if finished {
                outer.idle();
                None
            } else {
                outer.control(period, drive_faults)
            };
            let hold = RateCommand {
                rate_mps: 0.0,
                accel_mps2: 0.0,
                safe_hold: true,
            };
            let out = cortex_m::interrupt::free(|cs| {
                // As in `SysTick`: the borrow cannot fail (critical section, one core).
                let mut inner = INNER.borrow(cs).try_borrow_mut().ok()?;
                inner.as_mut().map(|i| {
                    i.pending = if finished { Some(hold) } else { cmd };
                    i.drive.output()
                })
            });

            // The controller's events went to the on-board computer (TM[5,x]); what the link
            // lost or refused is logged here when it grows.
            let link = outer.obc.counters();
            let losses = link.losses();
            if losses != link_losses {
                defmt::warn!("t={=u32} on-board computer link: {}", period, link);
                link_losses = losses;
            }
            if finished {
                if period as usize == SAMPLES.len() {
                    defmt::info!("replay done: drive in safe hold");
                }
            } else if period.is_multiple_of(LOG_EVERY_PERIODS) {
                let o = outer.controller.output();
                if let Some(d) = out {
                    defmt::info!(
                        "t={=u32} {} {}: cmd={=f32} m/s drum={=f32} m/s ref={=f32} m/s duty={=f32} T={=f32} N brake={} faults={} overruns inner={=u32} outer={=u32} tc={=u32} tm={=u32}",
                        period,
                        o.phase,
                        o.health,
                        o.rate_cmd_mps,
                        d.speed_mps,
                        d.ref_rate_mps,
                        d.duty,
                        d.tension_n,
                        d.brake,
                        d.faults,
                        INNER_OVERRUNS.load(Ordering::Relaxed),
                        outer_overruns,
                        link.telecommands,
                        link.telemetry_sent
                    );
                }
            }
            period = period.saturating_add(1);
        }
    }

    /// The inner loop: one speed-loop step per SysTick.
    #[exception]
    fn SysTick() {
        let tick = INNER_TICKS.load(Ordering::Relaxed).wrapping_add(1);
        INNER_TICKS.store(tick, Ordering::Release);
        cortex_m::interrupt::free(|cs| {
            // `try_borrow_mut`, not `borrow_mut`: every borrow is inside a critical section on a
            // single core, so none can overlap and the `Err` arm never runs; it keeps the
            // panic path of `borrow_mut` out of the inner loop (scripts/panic-check).
            if let Ok(mut guard) = INNER.borrow(cs).try_borrow_mut() {
                if let Some(inner) = guard.as_mut() {
                    if let Some(cmd) = inner.pending.take() {
                        // A rejected command (non-finite) is a drive fault the speed loop
                        // reports; the drive keeps the previous one.
                        let _ = inner.drive.set_command(cmd, tick);
                    }
                    let _ = inner.drive.tick(tick);
                    inner.period_faults =
                        inner.period_faults.union(inner.drive.speed_loop().faults());
                }
            }
        });
        // SysTick already pending again: this step took longer than an inner period.
        if SCB::is_pendst_pending() {
            INNER_OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The on-board computer's line: bytes between USART2's FIFOs and [`ObcLine`]'s queues.
    #[interrupt]
    fn USART2() {
        cortex_m::interrupt::free(|cs| {
            // As in `SysTick`: the borrow cannot fail (critical section, one core).
            if let Ok(mut line) = OBC_LINE.borrow(cs).try_borrow_mut() {
                line.move_bytes();
            }
        });
    }

    /// Any fault (a panic reaches here through panic-probe's `udf`): log, and reset into the
    /// safe state (all pins inputs: driver off, spring brake engaged).
    #[allow(unsafe_code)] // cortex-m-rt requires `unsafe fn` for the HardFault handler.
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        defmt::error!(
            "HardFault: pc = {=u32:#010x}, lr = {=u32:#010x}; resetting",
            frame.pc(),
            frame.lr()
        );
        SCB::sys_reset()
    }

    /// An interrupt with no handler: log it and reset as [`HardFault`] does.
    #[allow(unsafe_code)] // cortex-m-rt requires `unsafe fn` for the default handler.
    #[exception]
    unsafe fn DefaultHandler(irqn: i16) {
        defmt::error!("unhandled interrupt: IRQn = {=i16}; resetting", irqn);
        SCB::sys_reset()
    }
}
