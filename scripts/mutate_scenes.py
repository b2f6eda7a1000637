#!/usr/bin/env python3
"""Mutation campaign over the example scenes (issue 17).

Usage: python3 scripts/mutate_scenes.py BIN N [SEED] [--run]

Each mutant is an example scene (deformable ones left out) with 1 to 3 edits: a
number set to 0, -1, ±1e308, nan, inf, 1e12, ...; a line deleted or duplicated;
the file truncated. `BIN check MUTANT` must exit 0 or 2 within 5 s: a panic, an
abort (another exit code) or a hang is written to target/mutants/ and printed.
With `--run`, a mutant that `check` accepts is also run for 20 steps
(`nscdd run --quiet`), which must exit 0, 1 (a reported divergence) or 2 within 20 s.
"""
import random, re, subprocess, sys, pathlib, os
RUN = '--run' in sys.argv
args = [a for a in sys.argv[1:] if a != '--run']
BIN = args[0]; N = int(args[1]); seed = int(args[2]) if len(args) > 2 else 1
random.seed(seed)
ROOT = pathlib.Path(__file__).resolve().parent.parent
scenes = [p for p in (ROOT / 'examples/scenes').glob('*.toml') if '[[deformable]]' not in p.read_text()]
texts = [(p, p.read_text()) for p in scenes]
VALUES = ['0', '-1', '1e308', '-1e308', 'nan', 'inf', '1e12', '1e9', '3', '0.0', '1e-300', '-0.0', '100000000', '2', '1.5']
num = re.compile(r'(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])')
out = ROOT / 'target/mutants'; out.mkdir(parents=True, exist_ok=True)
bad = 0
runs = 0
for k in range(N):
    if k and k % 1000 == 0:
        print(f'{k} mutants, {runs} runs, {bad} bad', flush=True)
    p, t = random.choice(texts)
    lines = t.splitlines()
    for _ in range(random.randint(1, 3)):
        op = random.random()
        if not lines: lines = [""]
        i = random.randrange(len(lines))
        if op < 0.6:
            ms = list(num.finditer(lines[i]))
            if ms:
                m = random.choice(ms)
                lines[i] = lines[i][:m.start()] + random.choice(VALUES) + lines[i][m.end():]
        elif op < 0.75:
            del lines[i]
        elif op < 0.9:
            lines.insert(i, lines[i])
        else:
            lines = lines[:i]
            if not lines: lines = ['']
    text = '\n'.join(lines) + '\n'
    f = pathlib.Path(f'/tmp/fuzz_{os.getpid()}.toml'); f.write_text(text)
    try:
        r = subprocess.run([BIN, 'check', str(f)], capture_output=True, text=True, timeout=5, cwd=str(p.parent))
        kind = None
        if 'panicked' in r.stderr: kind = 'panic'
        elif r.returncode not in (0, 2): kind = f'rc{r.returncode}'
        elif RUN and r.returncode == 0:
            short = re.sub(r'(?m)^(steps|duration) = .*$', 'steps = 20', text)
            f.write_text(short)
            runs += 1
            outdir = f'/tmp/fuzz_out_{os.getpid()}'
            try:
                r = subprocess.run([BIN, 'run', str(f), '--quiet', '--out', outdir], capture_output=True, text=True, timeout=20, cwd=str(p.parent))
                if 'panicked' in r.stderr: kind = 'run-panic'
                elif r.returncode not in (0, 1, 2): kind = f'run-rc{r.returncode}'
            except subprocess.TimeoutExpired:
                kind = 'run-hang'; r = None
            text = short
    except subprocess.TimeoutExpired:
        kind = 'hang'; r = None
    if kind:
        bad += 1
        dst = out / f'{kind}_{seed}_{k}_{p.stem}.toml'; dst.write_text(text)
        msg = next((l for l in r.stderr.splitlines() if 'panicked' in l or 'alloc' in l or 'overflow' in l), (r.stderr.strip().splitlines() or [''])[0])[:200] if r else ''
        print(kind, dst.name, msg, flush=True)
print(f'{bad} bad of {N} mutants ({runs} accepted and run)')
