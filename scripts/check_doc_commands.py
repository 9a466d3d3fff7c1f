#!/usr/bin/env python3
"""Every command line the docs show must still be accepted: each `build/bin/APP ...` in README.md and
docs/**/*.md, and each line under "Examples:" in an app's --help (which, where the app has --check, must
also pass it), names an existing app, each --flag it uses is one the app's --help lists, and each --set KEY is
a scene key (spread --list-keys) whose documented value `spread --check` accepts, and each scenes/*.toml it
names exists.
Usage: check_doc_commands.py SOURCE_DIR BIN_DIR [DOC.md ...]   (default: README.md and docs/**/*.md)
Exit 0 when every command holds, 1 listing each problem as FILE:LINE: what."""
import pathlib, re, subprocess, sys

if any(a in ("-h", "--help") for a in sys.argv[1:]):
    print(__doc__.strip())
    sys.exit(0)
if len(sys.argv) < 3:
    sys.exit("usage: check_doc_commands.py SOURCE_DIR BIN_DIR [DOC.md ...]   (--help: what it checks)")
src, bindir = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
docs = [pathlib.Path(d).resolve() for d in sys.argv[3:]] or [src / "README.md"] + sorted((src / "docs").rglob("*.md"))
# A command runs from `build/bin/APP` to the closing backtick of its code span (which may wrap lines).
cmd_re = re.compile(r"build/bin/([A-Za-z_][A-Za-z0-9_-]*)([^`]*)")
flag_re = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")
set_re = re.compile(r"--set[\s=]+([a-z_][A-Za-z0-9_.]*)=([^\s\]`]*)")

def is_command_head(before):
    """True when what precedes build/bin/APP in its code span is only environment settings, `time` or
    `timeout N`, after the start of the span or a shell separator."""
    segment = re.split(r"[;&|(]", before)[-1].split()
    words = [w for w in segment if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*=\S*", w)]
    return all(w in ("time", "env", "timeout") or w.isdigit() for w in words)


help_cache, problems, checked, pairs = {}, [], 0, {}
def app_help(app):
    if app not in help_cache:
        exe = bindir / app
        if not exe.exists():
            help_cache[app] = None
        else:
            try:
                r = subprocess.run([str(exe), "--help"], capture_output=True, text=True, timeout=60)
                help_cache[app] = r.stdout + r.stderr
            except subprocess.TimeoutExpired:
                help_cache[app] = ""
                problems.append(f"build/bin/{app} --help did not answer in 60 s")
    return help_cache[app]

keys_out = subprocess.run([str(bindir / "spread"), "--list-keys"], capture_output=True, text=True,
                          timeout=60).stdout
keys = set(re.findall(r"^\| `([A-Za-z_0-9.]+)`", keys_out, re.M))
if len(keys) < 20:
    sys.exit(f"spread --list-keys gave {len(keys)} keys; cannot check")

def check_command(app, rest, where):
    h = app_help(app)
    if h is None:
        problems.append(f"{where}: build/bin/{app} does not exist")
        return
    gtest_or_bench = "--gtest_" in h or "--benchmark_" in h
    for flag in flag_re.findall(rest):
        if gtest_or_bench and (flag.startswith("--gtest_") or flag.startswith("--benchmark_")):
            continue
        if not re.search(re.escape(flag) + r"(?![a-z0-9-])", h):
            problems.append(f"{where}: build/bin/{app} has no option {flag}")
    for scene in re.findall(r"(?<![\w/.-])((?:scenes|tests)/[\w/.-]+\.toml)", rest):
        if not (src / scene).exists():
            problems.append(f"{where}: {scene} does not exist")
    sets = set_re.findall(rest)
    for key, value in sets:
        if key not in keys:
            problems.append(f"{where}: --set {key}: not a scene key")
        elif re.fullmatch(r"[-+.\w\"']+", value) and not re.fullmatch(r"[A-Z]+", value):
            # checked by the command's own app when it has --check (apps differ: spread needs the plane)
            checker = app if re.search(r"--check(?![a-z-])", h) else "spread"
            # with the command's other --set pairs: a value allowed only together with another (a start gap
            # beyond the range with gravity on) is checked alone first, then in its command
            pairs.setdefault((checker, key, value), (where, [f"{k}={v}" for k, v in sets]))


for doc in docs:
    text = doc.read_text()
    for span in re.finditer(r"`([^`]+)`", text, re.S):
        spans = span.group(1)
        for m in cmd_re.finditer(spans):
            app, rest = m.group(1), m.group(2)
            if not is_command_head(spans[: m.start()]):
                continue  # build/bin/APP passed as an argument (e.g. to a script): not this app's options
            rest = rest.split("build/bin/")[0]  # stop at the next command of a pipeline
            where = f"{doc.name if not doc.is_relative_to(src) else doc.relative_to(src)}:{text.count(chr(10), 0, span.start(1) + m.start()) + 1}"
            checked += 1
            check_command(app, rest, where)

# The examples in the apps' own --help (only when checking the docs, not a fixture).
if not sys.argv[3:]:
    for exe in sorted(bindir.iterdir()):
        if not (exe.is_file() and exe.stat().st_mode & 0o111) or exe.suffix:
            continue
        h = app_help(exe.name)
        if "Examples:" not in h:
            continue
        for line in h.split("Examples:", 1)[1].splitlines()[1:]:
            words = line.split(None, 1)
            if not line.startswith("  ") or not words or words[0] != exe.name:
                break
            checked += 1
            args = words[1] if len(words) > 1 else ""
            check_command(exe.name, args, f"{exe.name} --help")
            # An app with --check must accept its own example as it stands (a restart needs its checkpoint).
            if re.search(r"--check(?![a-z-])", h) and "--restart" not in args:
                try:
                    r = subprocess.run([str(exe)] + args.split() + ["--check", "--quiet"], capture_output=True,
                                       text=True, timeout=60, cwd=src)
                    if r.returncode != 0:
                        problems.append(f"{exe.name} --help: example `{line.strip()}`: "
                                        f"{(r.stderr or r.stdout).strip()}")
                except subprocess.TimeoutExpired:
                    problems.append(f"{exe.name} --help: example `{line.strip()}`: --check did not answer in 60 s")

# The values: each documented KEY=VALUE (placeholders such as N or <run> left out) must pass spread --check,
# alone or with the other --set pairs of the command that shows it.
def check_sets(checker, sets):
    args = [a for kv in sets for a in ("--set", kv)]
    return subprocess.run([str(bindir / checker), "--check", "--quiet"] + args, capture_output=True, text=True,
                          timeout=60, cwd=src)


for (checker, key, value), (where, context) in sorted(pairs.items()):
    try:
        r = check_sets(checker, [f"{key}={value}"])
        if r.returncode != 0 and len(context) > 1 and check_sets(checker, context).returncode == 0:
            continue
        if r.returncode != 0:
            problems.append(f"{where}: --set {key}={value}: {(r.stderr or r.stdout).strip()}")
    except subprocess.TimeoutExpired:
        problems.append(f"{where}: --set {key}={value}: {checker} --check did not answer in 60 s")

for p in problems:
    print(p)
print(f"{checked} documented commands checked, {len(problems)} problems")
sys.exit(1 if problems or checked == 0 else 0)
