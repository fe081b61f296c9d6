#!/usr/bin/env python3
"""Where the instructions of one control tick go, in the flight firmware itself.

Runs a firmware ELF in QEMU (mps2-an386) with one instruction per translation block and the
execution log on (`-singlestep -d exec,nochain`), cuts the log at SysTick entries into SysTick
periods (1 ms: SysTick runs the speed loop at 1 kHz, and every thousandth period also holds a
control step), and attributes every instruction of period N to the source function it came from, through
the inlining chain (llvm-symbolizer --inlining). So the breakdown is that of the flight codegen,
with everything LLVM inlined into `Controller::step` sorted back into the paper's pieces.

    tools/trace_profile.py [--elf ELF] [--tick N | --mission-tick N] [--top K]
                           [--lines [--within REGEX]]

--lines adds the instructions per source line (innermost frame, with its inlining chain);
--within REGEX keeps only the lines of the categories or stages matching REGEX (e.g. "Monitor",
"report"); each line is prefixed by its stage of the step.

--mission-tick N profiles step N of the whole 20-h paper mission instead: the subject is
examples/trace_step.rs (one `Controller::step` a tick, built with the flight profile:
`cargo build --profile firmware --target thumbv7em-none-eabihf --features firmware
--example trace_step`; built with TSS_TRACE_REPLAY=1 it flies the firmware's 720-s replay
instead, and N is a step of the replay, as in examples/bench_step.rs), and the
instructions counted are those from the N-th entry into `Controller::run` (the step: decide,
then report; or `Controller::step` or `::decide`, whichever LLVM kept as a function) to the
return to the caller. The trace is streamed through a pipe, not stored (a late step is some 4·10^7 lines in).

Defaults: the flight firmware (target/thumbv7em-none-eabihf/firmware/tss-reel, build it with
`cargo fw-build`), SysTick period 301. Needs qemu-system-arm
and llvm-symbolizer (Debian: apt-get install llvm). Either trace is streamed through a pipe,
never stored (the firmware's SysTick runs the 1 kHz speed loop, so a late period is some 10^8
lines in). Figures only; not part of CI.
"""
import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile

# (category, pattern over the inlining chain, innermost first); the first match wins.
CATEGORIES = [
    ("estimator: drive checks (stretch)", r"Estimator.*::stretch|estimator::refusal"),
    ("estimator: covariance propagation (Φ P Φᵀ + Q, caps)", r"Sym3.*::(propagated|rounding_loaded|plus|cap)"),
    ("estimator: covariance update (P − K pᵀ, α row r K)", r"Sym3.*::posterior"),
    ("estimator: prediction (Ψ, Φ, the state)", r"Estimator.*::predict"),
    ("estimator: update (gate, gain, state)", r"Estimator.*::update"),
    ("estimator: the rest", r"estimator::"),
    ("estimator's wiring (controller::estimation)", r"controller::estimation::|Controller.*::estimate_swing"),
    ("schedule (α_r: BandSchedule/SlewedSchedule)", r"schedule::|Controller.*::reference"),
    ("law::solve: fastmath::sin_cos", r"fastmath::sin_cos.*law::solve"),
    ("law::solve: the square root (tss_fpu, VSQRT.F32)", r"sqrt.*law::solve"),
    ("law::solve: the rest", r"law::solve"),
    ("law::acceleration", r"law::acceleration"),
    ("envelope: the square root", r"sqrt.*(Envelope|envelope::)"),
    ("envelope: the rest", r"Envelope|envelope::"),
    ("blend E and 1 - E (Eq. 29: carried a period, or 2^(-cτ·log2 e) after a gap)", r"expf|fastmath::exp|blend_weight|Blend|Sequencer.*::carry_blend_to"),
    ("mass model (coefficients, mu3_rate)", r"MassModel"),
    ("existence check (Eq. 13 margin)", r"equilibrium::|equilibrium_margin"),
    ("sensor validation (Monitor::check)", r"Monitor.*::check"),
    ("the square root (other)", r"sqrt"),
    ("controller: sequencer, health, dead reckoning, output", r"controller::"),
    ("HAL: control_cycle, replay sensors, telemetry digest", r"hal::|Replay|TelemetryReel|control_cycle"),
    ("mission/main loop, clock, SysTick", r"mission::|clock::|SysTick|main|wfi|interrupt"),
]


def demangle_short(name):
    for _ in range(5):
        name = re.sub(r"<[^<>]*>", "", name)
    name = re.sub(r"::h[0-9a-f]{16}$", "", name)
    return name.replace("$LT$", "<").replace("$GT$", ">")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--elf", default="target/thumbv7em-none-eabihf/firmware/tss-reel")
    ap.add_argument("--tick", type=int, default=301)
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--lines", action="store_true",
                    help="also count instructions per source line (innermost frame)")
    ap.add_argument("--within", default="",
                    help="with --lines: only instructions whose category matches this regex")
    ap.add_argument("--mission-tick", type=int, default=None,
                    help="profile step N of the paper mission (examples/trace_step.rs)")
    a = ap.parse_args()
    if a.mission_tick is not None:
        if a.elf == ap.get_default("elf"):
            a.elf = "target/thumbv7em-none-eabihf/firmware/examples/trace_step"
        pcs = mission_step_pcs(a.elf, a.mission_tick)
        what = f"mission step {a.mission_tick}: {len(pcs)} instructions, Controller::decide entry to return"
    else:
        pcs = firmware_tick_pcs(a.elf, a.tick)
        what = f"tick {a.tick}: {len(pcs)} instructions, SysTick entry to SysTick entry"
    profile(a, pcs, what)


QEMU = ["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic",
        "-semihosting-config", "enable=on,target=native",
        "-icount", "shift=5,align=off,sleep=off", "-singlestep", "-d", "exec,nochain"]
PC = re.compile(r"Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")


def trace_pcs(lines):
    """(pc, line) of each executed instruction. With -icount, QEMU sometimes logs a block,
    stops before executing it (the instruction budget ran out) and logs it again when it does:
    a PC repeated on consecutive lines is one execution (the code has no branch-to-self)."""
    prev = None
    for line in lines:
        m = PC.match(line)
        if not m:
            continue
        pc = int(m.group(1), 16)
        if pc != prev:
            yield pc, line
        prev = pc


def mission_step_pcs(elf, n):
    """The PCs of the n-th call of Controller::decide (n counts from 0), read from a pipe:
    from its entry to the return to the caller (the instruction after the caller's `bl`)."""
    nm = subprocess.run(["llvm-nm", "--defined-only", elf], capture_output=True,
                        text=True, check=True).stdout
    # Controller::run (legacy mangling: decide, then report), or Controller::step where run is
    # inlined into it, or Controller::decide where neither is a function of its own.
    entries = []
    for name in ("3run17h", "4step17h", "6decide17h"):
        entries = entries or [int(l.split()[0], 16) & ~1 for l in nm.splitlines()
                              if "Controller" in l and name in l]
    if len(entries) != 1:
        sys.exit(f"trace_profile: expected one Controller::run, ::step or ::decide in {elf}, found {len(entries)}")
    entry = entries[0]
    with tempfile.TemporaryDirectory() as tmp:
        fifo = os.path.join(tmp, "trace.fifo")
        os.mkfifo(fifo)
        qemu = subprocess.Popen(QEMU + ["-D", fifo, "-kernel", elf],
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        pcs, calls, prev, ret = [], -1, None, None
        try:
            with open(fifo) as f:
                for pc, _ in trace_pcs(f):
                    if pc == entry:
                        calls += 1
                        if calls == n:
                            ret = prev + 4  # after the caller's 32-bit `bl`
                    if ret is not None:
                        if pc == ret:
                            break
                        pcs.append(pc)
                    prev = pc
        finally:
            qemu.kill()
            qemu.wait()
    if not pcs:
        sys.exit(f"trace_profile: mission step {n} not reached")
    return pcs


def firmware_tick_pcs(elf, tick):
    """The PCs of SysTick period `tick` of the firmware: SysTick entry to the next one, read
    from a pipe (QEMU stops as soon as the period has passed)."""
    with tempfile.TemporaryDirectory() as tmp:
        fifo = os.path.join(tmp, "trace.fifo")
        os.mkfifo(fifo)
        qemu = subprocess.Popen(QEMU + ["-D", fifo, "-kernel", elf],
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        pcs, ticks, prev = [], -1, None
        try:
            with open(fifo) as f:
                for pc, line in trace_pcs(f):
                    name = line.rsplit("]", 1)[1].strip()
                    if name == "SysTick" and prev != "SysTick":
                        ticks += 1
                        if ticks == tick + 1:
                            break
                    prev = name
                    if ticks == tick:
                        pcs.append(pc)
        finally:
            qemu.kill()
            qemu.wait()
    if not pcs:
        sys.exit(f"trace_profile: tick {tick} not reached")
    return pcs


def stage_of(chain):
    """The step's stage an instruction belongs to: the outermost method of `Controller` in its
    inlining chain other than the step's own entry points (`step`, `run`, `decide`)."""
    for fn in reversed(chain):
        m = re.search(r"Controller<T>>?::(\w+)", fn)
        if m and m.group(1) not in ("step", "step_missing", "run", "decide"):
            return m.group(1)
    return "(the step itself: " + chain[-1] + ")" if chain else "?"


def profile(a, pcs, what):
    """Prints the instructions of `pcs` by category, innermost function and source line."""
    # Function extents, to follow calls into functions LLVM kept out of line (libm's sqrtf,
    # expf, the compiler's soft-float helpers): a shadow call stack over the trace.
    nm = subprocess.run(["llvm-nm", "-S", "--defined-only", a.elf], capture_output=True,
                        text=True, check=True).stdout
    extent = {}
    for line in nm.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTwW":
            start = int(parts[0], 16) & ~1
            extent[start] = start + int(parts[1], 16)

    uniq = sorted(set(pcs))
    out = subprocess.run(
        ["llvm-symbolizer", "--inlining", "--functions=linkage", "--demangle", "--obj=" + a.elf],
        input="\n".join(f"0x{p:x}" for p in uniq), capture_output=True, text=True, check=True
    ).stdout
    chains, where = {}, {}
    for pc, block in zip(uniq, out.strip().split("\n\n")):
        lines = block.split("\n")
        chains[pc] = [demangle_short(lines[i]) for i in range(0, len(lines) - 1, 2)]
        where[pc] = re.sub(r"^.*/(src|examples)/", r"\1/", lines[1]) if len(lines) > 1 else "?"

    by_cat, by_fn, by_line = collections.Counter(), collections.Counter(), collections.Counter()
    by_stage = collections.Counter()
    stack, prev_pc = [], None  # [(start, end, caller's chain)]
    for pc in pcs:
        while stack and not stack[-1][0] <= pc < stack[-1][1]:
            stack.pop()
        if pc in extent and prev_pc is not None and not pc <= prev_pc < extent[pc]:
            caller = chains[prev_pc] + (stack[-1][2] if stack else [])
            stack.append((pc, extent[pc], caller))
        prev_pc = pc
        full = chains[pc] + (stack[-1][2] if stack else [])
        chain = " < ".join(full)
        cat = next((c for c, p in CATEGORIES if re.search(p, chain)), "other: " + full[-1])
        by_cat[cat] += 1
        by_fn[chains[pc][0]] += 1
        stage = stage_of(full)
        by_stage[stage] += 1
        if re.search(a.within, cat) or re.search(a.within, stage):
            by_line[stage + ": " + where[pc] + "  [" + " < ".join(chains[pc][:3]) + "]"] += 1
    total = len(pcs)
    print(f"{a.elf}: {what}")
    for cat, n in by_cat.most_common():
        print(f"  {n:6d}  {100 * n / total:5.1f} %  {cat}")
    print("by stage of the step (the outermost `Controller` method below run/decide):")
    for stage, n in by_stage.most_common():
        print(f"  {n:6d}  {100 * n / total:5.1f} %  {stage}")
    print(f"innermost source functions (top {a.top}):")
    for fn, n in by_fn.most_common(a.top):
        print(f"  {n:6d}  {fn}")
    if a.lines:
        print(f"source lines (top {a.top}):")
        for line, n in by_line.most_common(a.top):
            print(f"  {n:6d}  {line}")


if __name__ == "__main__":
    main()
