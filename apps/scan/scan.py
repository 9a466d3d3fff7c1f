#!/usr/bin/env python3
"""scan: a parameter scan of spread runs (the paper's Figure 5 kind), described by a scan file.

Every member is a spread run of its own, run by a pool of processes (--jobs at a time, each with --threads OpenMP
threads). With --chunk N up to N members run as one batch (spread --batch: the members are cells of one model,
one kernel launch for all, each member's outputs the same as alone; docs/SCANS.md); a batch that fails runs its
members again one by one. Started by mpirun (mpirun -np P scan ...), the ranks share the members out (rank 0
hands them out on request), each rank runs its share with its own pool, and rank 0 writes the one set of outputs.

  scan SCAN.toml [--out DIR] [--jobs N] [--threads T] [--chunk N] [--dry-run] [--no-plot] [--quiet]

Outputs in DIR (default out/<scan name>): members/<id>/ (each member's spread output), summary.csv (one row per
member: id, status, the swept keys, the summary values), scan.h5 (a group per member: its parameters and
summary as attributes, its series and final frame), scan.json (the members and their resolved --set
arguments) and r_cc_grid.png (r_cc(t) per swept key; a latin_hypercube scan also sensitivity.png, the final
r_cc and contact angle against each swept key). Running the same command again finishes what is
missing: finished members are kept, interrupted ones continue from their checkpoint.
Exit codes: 0 all members finished, 1 a member failed otherwise (a crash, a full disk: its spread.log says why),
2 bad input (nothing written), 3 a member failed numerically, 130 stopped.
"""
import argparse, csv, errno, hashlib, itertools, json, math, os, random, shutil, signal, subprocess, sys, tempfile, time

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

PROG = "scan"
# The model's version for member folders: a change of spread's physics defaults makes an earlier member's results
# another model's (29: Table 1's c read as the membrane's shear viscosity). member.json records it; a folder of
# another version runs again.
PHYSICS = 29
# Whether spread was built for a GPU (a Kokkos with CUDA, HIP or SYCL): apps/scan/CMakeLists.txt sets it when
# it copies this file into the build. The environment variable DCM_SCAN_DEVICE_BUILD (0 or 1) overrides it.
DEVICE_BUILD = False  # set by the build
SUMMARY_KEYS = ["r_cc_final_m", "contact_angle_deg", "contact_angle_free_deg", "early_exponent",
                "early_window_cut_at_s", "contact_onset_s", "late_exponent", "r_cc_growth_last_tenth",
                "r_cc_growth_since_contact_nodes_most_m", "mesh_edge_mean_m", "height_final_m", "steps", "wall_s",
                "mean_cg_iterations"]


class ScanError(Exception):
    pass


def fmt(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def range_number(key, spec, field):
    """sweep.<key>.<field> of a range as a finite float; ScanError naming it otherwise."""
    if field not in spec:
        raise ScanError(f"sweep.{key} = {spec}: a range needs {field} (a finite number)")
    value = spec[field]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ScanError(f"sweep.{key}.{field} = {value!r} is not allowed: a finite number")
    return float(value)


def sweep_values(key, spec):
    if isinstance(spec, list):
        if not spec:
            raise ScanError(f"sweep.{key} = [] is empty: give at least one value")
        seen = []
        for v in spec:
            if v in seen:  # two identical members: the same run twice
                raise ScanError(f"sweep.{key} = {spec!r}: the value {v!r} appears twice; give each value once")
            seen.append(v)
        return spec
    if isinstance(spec, dict):
        allowed = {"start", "stop", "num", "spacing"}
        extra = set(spec) - allowed
        if extra:
            raise ScanError(f"sweep.{key}: unknown field '{sorted(extra)[0]}' (allowed: start, stop, num, spacing)")
        start, stop = range_number(key, spec, "start"), range_number(key, spec, "stop")
        num = spec.get("num")
        if isinstance(num, bool) or not isinstance(num, int):
            raise ScanError(f"sweep.{key} = {spec}: a range needs an integer num (1 .. 1000)")
        spacing = spec.get("spacing", "linear")
        if not 1 <= num <= 1000:
            raise ScanError(f"sweep.{key}.num = {num} is out of range: allowed 1 .. 1000")
        if spacing not in ("linear", "log"):
            raise ScanError(f"sweep.{key}.spacing = '{spacing}' is not allowed: choose linear or log")
        if spacing == "log" and not (start > 0 and stop > 0):
            raise ScanError(f"sweep.{key}: log spacing needs start > 0 and stop > 0 (got {start}, {stop})")
        if num > 1 and start == stop:  # num identical members: the same run num times
            raise ScanError(f"sweep.{key} = {spec}: start = stop gives {num} identical members; use num = 1")
        if num == 1:
            values = [start]
        elif spacing == "log":
            a, b = math.log(start), math.log(stop)
            values = [math.exp(a + (b - a) * i / (num - 1)) for i in range(num)]
        else:
            values = [start + (stop - start) * i / (num - 1) for i in range(num)]
        if num > 1:  # the ends are start and stop themselves, the rest to 12 digits (no 0.0020000000000000005)
            values = [start] + [float(f"{v:.12g}") for v in values[1:-1]] + [stop]
        if isinstance(spec["start"], int) and isinstance(spec["stop"], int):  # an integer key (mesh.nodes, ...)
            if any(v != round(v) for v in values):
                raise ScanError(f"sweep.{key} = {spec}: integer start and stop give values that are not whole "
                                f"numbers; give a list of integers or floats for start and stop")
            values = [int(round(v)) for v in values]
        if len(set(values)) != len(values):
            raise ScanError(f"sweep.{key} = {spec}: two members get the same value; give fewer num")
        return values
    raise ScanError(f"sweep.{key} = {spec!r}: give a list of values or a table {{start, stop, num, spacing}}")


def lhs_range(key, spec):
    """(start, stop, spacing) of a latin_hypercube sweep entry: a range without num."""
    if not isinstance(spec, dict):
        raise ScanError(f"sweep.{key} = {spec!r}: mode latin_hypercube samples ranges: give {{start, stop, spacing}}")
    extra = set(spec) - {"start", "stop", "spacing"}
    if extra:
        what = ("the scan's `samples` sets how many members there are" if extra == {"num"}
                else "allowed: start, stop, spacing")
        raise ScanError(f"sweep.{key}: field '{sorted(extra)[0]}' is not used by mode latin_hypercube ({what})")
    start, stop = range_number(key, spec, "start"), range_number(key, spec, "stop")
    spacing = spec.get("spacing", "linear")
    if spacing not in ("linear", "log"):
        raise ScanError(f"sweep.{key}.spacing = '{spacing}' is not allowed: choose linear or log")
    if spacing == "log" and not (start > 0 and stop > 0):
        raise ScanError(f"sweep.{key}: log spacing needs start > 0 and stop > 0 (got {start}, {stop})")
    if not start < stop:
        raise ScanError(f"sweep.{key}: start = {start} must be below stop = {stop}")
    return start, stop, spacing


def latin_hypercube(ranges, samples, seed):
    """samples members; for every key each of the samples equal strata of its range (equal in log for log
    spacing) holds exactly one member, at a uniformly random place inside it; strata paired at random between
    keys. Deterministic for a given seed (Python's Mersenne Twister)."""
    rng = random.Random(seed)
    columns = {}
    for key, (start, stop, spacing) in ranges.items():
        strata = list(range(samples))
        rng.shuffle(strata)
        values = []
        for s_i in strata:
            u = (s_i + rng.random()) / samples
            if spacing == "log":
                values.append(math.exp(math.log(start) + u * (math.log(stop) - math.log(start))))
            else:
                values.append(start + u * (stop - start))
        columns[key] = values
    return [{k: columns[k][i] for k in ranges} for i in range(samples)]


def load_scan(path):
    if tomllib is None:
        raise ScanError("this Python has no tomllib (needs Python >= 3.11)")
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except FileNotFoundError:
        raise ScanError(f"{path}: no such scan file")
    except IsADirectoryError:
        raise ScanError(f"{path}: is a folder, not a scan file")
    except OSError as e:
        raise ScanError(f"{path}: cannot be read: {e.strerror}")
    except UnicodeDecodeError:
        raise ScanError(f"{path}: not valid TOML: not UTF-8 text")
    except tomllib.TOMLDecodeError as e:
        raise ScanError(f"{path}: not valid TOML: {e}")
    allowed = {"name", "base", "mode", "set", "sweep", "samples", "seed"}
    for k in doc:
        if k not in allowed:
            raise ScanError(f"{path}: unknown key '{k}' (allowed: {', '.join(sorted(allowed))})")
    name = doc.get("name", os.path.splitext(os.path.basename(path))[0])
    if not isinstance(name, str) or not name or name in (".", "..") or any(c in name for c in "/\\ "):
        raise ScanError(f"{path}: name = {name!r} is not allowed: a non-empty word without / or spaces")
    base = doc.get("base")
    if base is not None and (not isinstance(base, str) or not base):
        raise ScanError(f"{path}: base = {base!r} is not allowed: the path of a scene file, in quotes")
    base_sha256 = ""  # the base scene's content: a member's results are its own only with the same base
    if base is not None:
        base = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), base))
        if not os.path.isfile(base):
            raise ScanError(f"{path}: base = '{doc['base']}': no such scene file ({base})")
        try:
            with open(base, "rb") as f:
                base_sha256 = hashlib.sha256(f.read()).hexdigest()
        except OSError as e:
            raise ScanError(f"{path}: base = '{doc['base']}': cannot be read: {e.strerror}")
    mode = doc.get("mode", "one_at_a_time")
    if mode not in ("one_at_a_time", "grid", "latin_hypercube"):
        raise ScanError(f"{path}: mode = '{mode}' is not allowed: choose one_at_a_time, grid or latin_hypercube")
    if mode != "latin_hypercube":
        for k in ("samples", "seed"):
            if k in doc:
                raise ScanError(f"{path}: {k} is used by mode latin_hypercube only (this scan's mode is {mode})")
    else:
        samples, seed = doc.get("samples"), doc.get("seed", 1)
        if samples is None:
            raise ScanError(f"{path}: mode latin_hypercube needs samples = N (2 .. 10000): the number of members")
        if not isinstance(samples, int) or isinstance(samples, bool) or not 2 <= samples <= 10000:
            raise ScanError(f"{path}: samples = {samples!r} is not allowed: mode latin_hypercube needs an integer "
                            f"samples, 2 .. 10000 (the number of members)")
        if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed < 2**63:
            raise ScanError(f"{path}: seed = {seed!r} is not allowed: an integer 0 .. 2^63 - 1")
    fixed = doc.get("set", {})
    sweep = doc.get("sweep", {})
    if not isinstance(fixed, dict) or not isinstance(sweep, dict):
        raise ScanError(f"{path}: [set] and [sweep] must be tables of scene keys")
    if not sweep:
        raise ScanError(f"{path}: [sweep] is empty: give at least one scene key with its values")
    for key in sweep:
        if key in fixed:
            raise ScanError(f"{path}: {key} is in both [set] and [sweep]: give it in one of them")
    for key in list(fixed) + list(sweep):
        if isinstance(fixed.get(key, sweep.get(key)), dict) and key in fixed:
            raise ScanError(f"{path}: set.{key}: write the key in quotes, e.g. \"{key}\" = value")
    if mode == "latin_hypercube":
        values = {k: lhs_range(k, v) for k, v in sweep.items()}
    else:
        values = {k: sweep_values(k, v) for k, v in sweep.items()}
    members = []  # (label, {key: value}) for the swept keys
    if mode == "latin_hypercube":
        members = latin_hypercube(values, samples, seed)
    elif mode == "grid":
        keys = list(values)
        for combo in itertools.product(*(values[k] for k in keys)):
            members.append(dict(zip(keys, combo)))
    else:
        members.append({})  # the base member: every swept key at the base scene's value
        for k, vs in values.items():
            for v in vs:
                members.append({k: v})
    out = []
    for i, swept in enumerate(members):
        sets = [f"{k}={fmt(v)}" for k, v in fixed.items()] + [f"{k}={fmt(v)}" for k, v in swept.items()]
        if mode == "latin_hypercube":  # random values: 4 digits in the label (the --set arguments keep them all)
            label = ", ".join(f"{k}={v:.4g}" for k, v in swept.items())
        else:
            label = ", ".join(f"{k}={fmt(v)}" for k, v in swept.items()) or "base"
        out.append({"id": f"m{i:03d}", "label": label, "swept": swept, "sets": sets, "base_sha256": base_sha256,
                    "physics": PHYSICS})
    return {"name": name, "base": base, "mode": mode, "sweep_keys": list(values), "members": out}


def spread_cmd(spread, scan, member, out_dir=None, extra=()):
    cmd = [spread] + ([scan["base"]] if scan["base"] else [])
    for s in member["sets"]:
        cmd += ["--set", s]
    if out_dir:
        cmd += ["--out", out_dir]
    return cmd + list(extra)


def same_member(stored, member):
    """True when a member.json's content describes `member`: the same --set values on a base scene of the same
    content, run by the same model version (a member folder of another base, of the base before an edit or of an
    earlier dcm whose defaults differ holds another run)."""
    return (stored.get("sets") == member["sets"] and stored.get("base_sha256") == member["base_sha256"]
            and stored.get("physics") == member["physics"])


def member_state(mdir, member):
    """done, resume (a checkpoint of the same member), or new."""
    try:
        with open(os.path.join(mdir, "member.json")) as f:
            if not same_member(json.load(f), member):
                return "new"
        with open(os.path.join(mdir, "summary.json")) as f:
            s = json.load(f)
        if not s.get("interrupted") and not s.get("stopped_at_max_steps"):
            return "done"
    except (OSError, ValueError, KeyError):
        pass
    return "resume" if os.path.isfile(os.path.join(mdir, "checkpoint.h5")) else "new"


def results_of(mdir, member):
    """True when mdir's files are this member's: its member.json holds the same sets and base. A folder left by
    an earlier scan file with other values or base (the member not launched in this run) is not reported."""
    try:
        with open(os.path.join(mdir, "member.json")) as f:
            return same_member(json.load(f), member)
    except (OSError, ValueError, KeyError, AttributeError):
        return False


def collect(scan, out, spread_ok):
    rows = []
    for m in scan["members"]:
        mdir = os.path.join(out, "members", m["id"])
        row = {"id": m["id"], "status": spread_ok.get(m["id"], "not run")}
        row.update({k: m["swept"].get(k, "") for k in scan["sweep_keys"]})
        try:
            if not results_of(mdir, m):
                raise OSError("another member's results")
            if row["status"].startswith("failed"):  # a failed restart leaves the interrupted run's summary
                raise OSError("no results of a failed run")
            with open(os.path.join(mdir, "summary.json")) as f:
                s = json.load(f)
            row.update({k: ("" if s.get(k) is None else s[k]) for k in SUMMARY_KEYS})  # null: not measured
            row["warnings"] = len(s.get("warnings", []))  # spread's end-of-run warnings (unresolved steps)
        except (OSError, ValueError):
            row.update({k: "" for k in SUMMARY_KEYS + ["warnings"]})
        rows.append(row)
    tmp = os.path.join(out, "summary.csv.part")
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["id", "status"] + scan["sweep_keys"] + SUMMARY_KEYS + ["warnings"])
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, os.path.join(out, "summary.csv"))
    return rows


def write_h5(scan, out, rows):
    try:
        import h5py
    except ImportError:
        print(f"{PROG}: warning: no h5py: scan.h5 not written", file=sys.stderr)
        return
    tmp = os.path.join(out, "scan.h5.part")
    with h5py.File(tmp, "w") as dst:
        dst.attrs["name"] = scan["name"]
        dst.attrs["mode"] = scan["mode"]
        g = dst.create_group("members")
        for m, row in zip(scan["members"], rows):
            mg = g.create_group(m["id"])
            mg.attrs["label"] = m["label"]
            mg.attrs["status"] = row["status"]
            mg.attrs["sets"] = json.dumps(m["sets"])
            for k, v in m["swept"].items():
                mg.attrs["param:" + k] = v
            for k in SUMMARY_KEYS + ["warnings"]:
                if row.get(k, "") != "":
                    mg.attrs[k] = row[k]
            if row["warnings"] != "":  # the summary was read: its null values (not measured), by name
                mg.attrs["null_keys"] = json.dumps([k for k in SUMMARY_KEYS if row.get(k, "") == ""])
            src_path = os.path.join(out, "members", m["id"], "spread.h5")
            if not os.path.isfile(src_path) or not results_of(os.path.dirname(src_path), m):
                continue
            try:
                with h5py.File(src_path, "r") as src:
                    if "series" in src:
                        src.copy(src["series"], mg, "series")
                    frames = sorted(src["frames"]) if "frames" in src else []
                    if frames:
                        src.copy(src["frames"][frames[-1]], mg, "final_frame")
                        if "mesh/triangles" in src:  # so that the final shape can be drawn from scan.h5 alone
                            src.copy(src["mesh/triangles"], mg["final_frame"], "triangles")
            except (OSError, KeyError) as e:  # a run killed while writing it (out of memory, a signal)
                print(f"{PROG}: warning: {src_path} cannot be read ({e}): member {m['id']} has no series in "
                      f"scan.h5", file=sys.stderr)
    os.replace(tmp, os.path.join(out, "scan.h5"))


def remove_plots(out, names=("r_cc_grid.png", "sensitivity.png")):
    """Removes an earlier scan's plots from out (they are not of the results being written)."""
    for png in names:
        if os.path.isfile(os.path.join(out, png)):
            os.remove(os.path.join(out, png))


def plot(scan, out):
    remove_plots(out)  # an earlier run's plots are not of these results, also when this plot fails
    plotter = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scan_plot.py")
    if not os.path.isfile(plotter):
        plotter = os.path.join(os.environ.get("DCM_SOURCE_DIR", ""), "apps", "scan", "scan_plot.py")
    r = subprocess.run([sys.executable, plotter, out], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"{PROG}: warning: r_cc_grid.png not written: {r.stderr.strip().splitlines()[-1:]}", file=sys.stderr)


# --- MPI (mpirun -np P scan ...): rank 0 hands out members one at a time (tag REQUEST -> MEMBER); every rank runs
# its members with its own process pool; each rank reports its statuses (and, without a shared file system, its
# members' files) with DONE; rank 0 alone writes summary.csv, scan.h5 and the plot. Ranks never write the same file.
TAG_REQUEST, TAG_MEMBER, TAG_DONE = 11, 12, 13
MEMBER_FILES_SKIPPED = {"checkpoint.h5"}  # what a rank without the shared file system does not send to rank 0


def mpi_comm():
    """MPI_COMM_WORLD when started by mpirun/mpiexec with more than one rank, else None."""
    if not any(k in os.environ for k in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS")):
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        raise ScanError("started by mpirun, but this Python has no mpi4py (apt-get install python3-mpi4py)")
    comm = MPI.COMM_WORLD
    return comm if comm.Get_size() > 1 else None


def ranks_on_this_machine(comm):
    if comm is None:
        return 1
    from mpi4py import MPI
    return comm.Split_type(MPI.COMM_TYPE_SHARED).Get_size()


def check_writable(out):
    """Raises ScanError when the folder `out` could not be created or written: a probe folder is made and removed
    in it or in its nearest existing parent (nothing is left)."""
    existing = out
    while not os.path.exists(existing) and os.path.dirname(existing) != existing:
        existing = os.path.dirname(existing)
    try:
        if not os.path.isdir(existing):
            raise NotADirectoryError(errno.ENOTDIR, f"{existing} is not a folder")
        os.rmdir(tempfile.mkdtemp(prefix=".dcm-check-", dir=existing))
    except OSError as e:
        raise ScanError(f"--out {out}: cannot write there ({e.strerror})")


def prepare(a):
    """Checks the arguments and every member's scene, writes scan.json; returns (scan, out). Raises ScanError."""
    if a.jobs < 0 or a.jobs > 1024:
        raise ScanError(f"--jobs = {a.jobs} is out of range: allowed 1 .. 1024 (0: the number of cores)")
    if a.chunk < 1 or a.chunk > 100000:
        raise ScanError(f"--chunk = {a.chunk} is out of range: allowed 1 .. 100000")
    if a.threads < 0 or a.threads > 1024:
        raise ScanError(f"--threads = {a.threads} is out of range: allowed 1 .. 1024 (0: cores / members run at once)")
    scan = load_scan(a.scan_file)
    out = os.path.abspath(a.out or os.path.join("out", scan["name"]))
    check_writable(out)
    refused = {}
    for m in scan["members"]:  # every member's scene and folder checked before anything is written
        try:
            r = subprocess.run(spread_cmd(a.spread, scan, m, out_dir=os.path.join(out, "members", m["id"]),
                                          extra=["--check"]), capture_output=True, text=True)
        except OSError as e:
            raise ScanError(f"cannot run spread ({a.spread}): {e.strerror}; run the build's bin/scan, which has "
                            f"spread beside it")
        if r.returncode != 0:
            msg = (r.stderr.strip().splitlines() or ["spread --check failed"])[-1]
            if not a.dry_run:
                raise ScanError(f"member {m['id']} ({m['label']}): {msg}")
            refused[m["id"]] = msg
    if a.dry_run:  # the list, and which members a run would refuse
        return scan, refused
    try:
        os.makedirs(os.path.join(out, "members"), exist_ok=True)
        with open(os.path.join(out, "scan.json.part"), "w") as f:
            json.dump(scan, f, indent=1)
        os.replace(os.path.join(out, "scan.json.part"), os.path.join(out, "scan.json"))
    except OSError as e:
        raise ScanError(f"--out {out}: cannot write there ({e.strerror})")
    return scan, out


def batch_word(w):
    """A word of a spread --batch member line: quoted, its backslashes and double quotes escaped."""
    return '"' + w.replace("\\", "\\\\").replace('"', '\\"') + '"'


def member_result(rc):
    """A member's status from its spread's exit code (a negative code: the signal that ended it)."""
    if rc in (130, -signal.SIGINT, -signal.SIGTERM):  # stopped (a signal before spread's handler was set)
        return "interrupted"
    if rc == 3:
        return "failed (numerical)"
    if rc < 0:
        return f"failed (killed by signal {-rc})"
    return "done" if rc == 0 else f"failed (exit {rc})"


def run_members(a, out, next_member, serve, jobs, threads, say):
    """Runs members as spread processes, jobs at a time, until next_member() returns None or a signal arrives;
    with a.chunk > 1 up to a.chunk new members share one process (spread --batch). serve() is called while waiting
    (rank 0 answers the other ranks there). Returns ({id: status}, stopped)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="false")
    for k in [k for k in env if k.startswith(("OMPI_", "PMIX_", "PMI_"))]:
        del env[k]  # the members are plain programs, not MPI ranks
    running, signalled, status = {}, set(), {}
    stop = False
    exhausted = False
    alone = []  # members of a failed batch: each runs again by itself
    batches = os.path.join(out, "batches")

    def take():
        return alone.pop(0) if alone else next_member()

    def launch(ms, cmd, log_path):
        for m in ms:
            mdir = os.path.join(out, "members", m["id"])
            os.makedirs(mdir, exist_ok=True)
            with open(os.path.join(mdir, "member.json"), "w") as f:
                json.dump({k: v for k, v in m.items() if k != "base"}, f, indent=1)
        log = open(log_path, "w")
        key = ms[0]["id"]
        running[key] = (subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT), ms, time.time(), log)

    def on_signal(sig, frame):
        nonlocal stop
        stop = True
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    while (not exhausted and not stop) or running:
        while not exhausted and not stop and len(running) < jobs:
            batch = []  # new members that run together
            while len(batch) < max(1, a.chunk):
                from_batch = bool(alone)
                m = take()
                if m is None:
                    exhausted = True
                    break
                mdir = os.path.join(out, "members", m["id"])
                state = member_state(mdir, m)  # on this rank's file system
                if state == "done":
                    status[m["id"]] = "done"
                    continue
                if batch and (state == "resume" or from_batch):  # it runs alone: the partial batch goes first,
                    alone.insert(0, m)                           # this member in the next free slot (--jobs)
                    break
                if state == "resume":  # a restart continues one run
                    launch([m], [a.spread, "--restart", os.path.join(mdir, "checkpoint.h5"), "--quiet", "--no-plot"],
                           os.path.join(mdir, "spread.log"))
                    break
                shutil.rmtree(mdir, ignore_errors=True)
                if from_batch:  # again by itself
                    launch([m], spread_cmd(a.spread, {"base": m["base"]}, m, mdir, ["--quiet", "--no-plot"]),
                           os.path.join(mdir, "spread.log"))
                    break
                batch.append(m)
            if len(batch) == 1:
                m = batch[0]
                mdir = os.path.join(out, "members", m["id"])
                launch([m], spread_cmd(a.spread, {"base": m["base"]}, m, mdir, ["--quiet", "--no-plot"]),
                       os.path.join(mdir, "spread.log"))
            elif batch:
                os.makedirs(batches, exist_ok=True)
                listing = os.path.join(batches, batch[0]["id"] + ".txt")
                with open(listing, "w") as f:
                    for m in batch:
                        words = spread_cmd("", {"base": m["base"]}, m, os.path.join(out, "members", m["id"]))[1:]
                        f.write(" ".join(batch_word(w) for w in words) + "\n")
                launch(batch, [a.spread, "--batch", listing, "--quiet", "--no-plot"],
                       os.path.join(batches, batch[0]["id"] + ".log"))
        serve(stop)
        time.sleep(0.05)
        for key, (p, ms, started, log) in list(running.items()):
            rc = p.poll()
            if rc is None:
                continue
            log.close()
            del running[key]
            result = member_result(rc)
            if len(ms) > 1:
                for m in ms:  # each member's log: the batch's
                    shutil.copyfile(log.name, os.path.join(out, "members", m["id"], "spread.log"))
                if rc not in (0, 130):
                    say(f"batch {', '.join(m['id'] for m in ms)}: {result} in {time.time() - started:.1f} s; "
                        f"its members run again one by one")
                    alone.extend(ms)
                    exhausted = False
                    continue
            for m in ms:
                status[m["id"]] = result
                say(f"{m['id']} {m['label']}: {result} in {time.time() - started:.1f} s"
                    + (f" (batch of {len(ms)})" if len(ms) > 1 else ""))
        if stop:  # each running member once: it writes its checkpoint and stops
            for mid, (p, *_) in running.items():
                if mid not in signalled and p.poll() is None:
                    p.send_signal(signal.SIGINT)
                    signalled.add(mid)
    return status, stop


def member_files(out, ids):
    """{id: {file name: bytes}} of the members' outputs (for rank 0 when the ranks share no file system)."""
    files = {}
    for mid in ids:
        mdir = os.path.join(out, "members", mid)
        files[mid] = {}
        for name in sorted(os.listdir(mdir)) if os.path.isdir(mdir) else []:
            path = os.path.join(mdir, name)
            if name not in MEMBER_FILES_SKIPPED and os.path.isfile(path):
                with open(path, "rb") as f:
                    files[mid][name] = f.read()
    return files


class OneLineParser(argparse.ArgumentParser):
    """A command-line error is one line on stderr and exit code 2, as in every dcm app (argparse prints its usage
    first)."""

    def error(self, message):
        sys.stderr.write(f"{self.prog}: error: {message} (see --help)\n")
        sys.exit(2)


def main():
    ap = OneLineParser(prog=PROG, description=__doc__.split("\n", 1)[1],
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="Example: scan scans/quick.toml --jobs 2 --threads 1   (4 members of 162 nodes, "
                              "under a minute on 2 cores)\n"
                              "Scan files: scans/quick.toml, scans/figure5.toml, scans/sensitivity.toml; modes "
                              "one_at_a_time, grid\nand latin_hypercube; format in docs/SCANS.md. "
                              "Over several machines: mpirun -np P scan SCAN.toml (docs/SCANS.md).")
    ap.add_argument("scan_file", metavar="SCAN.toml")
    ap.add_argument("--out", help="output folder (default out/<scan name>)")
    ap.add_argument("--jobs", type=int, default=0,
                    help="members run at once (per MPI rank; 0, the default: the cores, shared among the ranks "
                         "on a machine, whatever OMP_NUM_THREADS says; 1 with a GPU build, where one process owns "
                         "the device: add --chunk N so that its batch fills it)")
    ap.add_argument("--threads", type=int, default=0,
                    help="OpenMP threads per member (0, the default: cores / members run at once)")
    ap.add_argument("--chunk", type=int, default=1,
                    help="members run as one batch (spread --batch; default 1: each member its own process)")
    ap.add_argument("--dry-run", action="store_true",
                    help="list the members and their --set arguments and check each (exit 2 if a run would refuse "
                         "one), run nothing")
    ap.add_argument("--no-plot", action="store_true", help="do not draw r_cc_grid.png (nor sensitivity.png)")
    ap.add_argument("--quiet", action="store_true", help="print only errors")
    ap.add_argument("--spread", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "spread"),
                    help=argparse.SUPPRESS)
    a = ap.parse_args()
    try:
        comm = mpi_comm()
    except ScanError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    rank = comm.Get_rank() if comm else 0
    size = comm.Get_size() if comm else 1

    # Rank 0 checks everything and creates the output folder; the others learn the outcome from it.
    prepared = None
    if rank == 0:
        try:
            prepared = prepare(a)
        except ScanError as e:
            print(f"{PROG}: error: {e}", file=sys.stderr)
    if comm:
        prepared = comm.bcast(prepared, root=0)
    if prepared is None:
        return 2
    scan, out = prepared
    if a.dry_run:  # `out` holds the refused members' messages here
        if rank == 0:
            for m in scan["members"]:
                print(m["id"], m["label"], " ".join(f"--set {s}" for s in m["sets"]))
            for mid, msg in out.items():
                print(f"{PROG}: member {mid}: {msg}", file=sys.stderr)
            if out:
                print(f"{PROG}: error: a run would refuse {len(out)} of {len(scan['members'])} members (above)",
                      file=sys.stderr)
        return 2 if out else 0

    cores = os.cpu_count() or 1
    per_rank_cores = max(1, cores // ranks_on_this_machine(comm))
    device = os.environ.get("DCM_SCAN_DEVICE_BUILD", "1" if DEVICE_BUILD else "0") == "1"
    jobs = a.jobs or (1 if device else per_rank_cores)
    if rank > 0 and os.environ.get("DCM_SCAN_PRIVATE_DISKS") == "1":  # tests: as if each rank had its own disk
        out = f"{out}.rank{rank}"
    shared = os.path.isfile(os.path.join(out, "scan.json"))  # rank 0 wrote it before the broadcast
    if not shared:
        os.makedirs(os.path.join(out, "members"), exist_ok=True)
    members = [dict(m, base=scan["base"]) for m in scan["members"]]
    t0 = time.time()
    prefix = f"[rank {rank}] " if comm else ""
    counter = [0]

    if rank == 0:
        queue = [m for m in members if member_state(os.path.join(out, "members", m["id"]), m) != "done"]
        n_todo = len(queue)
        status = {m["id"]: "done" for m in members if all(m["id"] != q["id"] for q in queue)}
        threads = a.threads or max(1, per_rank_cores // max(1, min(jobs, math.ceil(n_todo / a.chunk))))
        if not a.quiet:
            changed = [m["id"] for m in queue if os.path.isfile(os.path.join(out, "members", m["id"], "member.json"))
                       and not results_of(os.path.join(out, "members", m["id"]), m)]
            if changed:
                print(f"{PROG}: {len(changed)} member folder(s) hold a run of other settings, another base scene or an "
                      f"earlier dcm (the scan file, its base or the model's defaults changed): "
                      f"run again: {' '.join(changed[:10])}{' ...' if len(changed) > 10 else ''}", flush=True)
            ids = {m["id"] for m in members}
            extra = sorted(d for d in os.listdir(os.path.join(out, "members")) if d not in ids)
            if extra:
                print(f"{PROG}: members/ also holds {' '.join(extra[:10])}{' ...' if len(extra) > 10 else ''}: not "
                      f"members of this scan, left as they are and not in its results", flush=True)
            where = f"; {size} MPI ranks" if comm else ""
            print(f"{PROG}: {scan['name']}: {len(members)} members, {len(members) - n_todo} already done; {jobs} at a "
                  f"time, {threads} thread(s) each{where} -> {out}", flush=True)
            if device and not a.jobs and a.chunk == 1 and n_todo > 1:
                print(f"{PROG}: GPU build: one process at a time owns the device; --chunk N runs N members in it as "
                      f"one batch (spread --batch)", flush=True)
        done_ranks, remote = set(), {}
        handed = {"stop": False}

        def next_local():
            return queue.pop(0) if queue and not handed["stop"] else None

        def serve(stop):
            handed["stop"] = handed["stop"] or stop
            if not comm:
                return
            from mpi4py import MPI
            st = MPI.Status()
            while comm.Iprobe(source=MPI.ANY_SOURCE, tag=MPI.ANY_TAG, status=st):
                src, tag = st.Get_source(), st.Get_tag()
                msg = comm.recv(source=src, tag=tag)
                if tag == TAG_REQUEST:
                    comm.send(next_local(), dest=src, tag=TAG_MEMBER)
                elif tag == TAG_DONE:
                    done_ranks.add(src)
                    remote.update(msg["status"])
                    for mid, files in msg["files"].items():
                        mdir = os.path.join(out, "members", mid)
                        shutil.rmtree(mdir, ignore_errors=True)  # no file of an earlier run next to these
                        os.makedirs(mdir, exist_ok=True)
                        for name, data in files.items():
                            with open(os.path.join(mdir, name), "wb") as f:
                                f.write(data)

        def say(text):
            counter[0] += 1
            if not a.quiet:  # under MPI each rank reports its own members
                print(f"{prefix}{text}" if comm else f"[{counter[0]}/{n_todo}] {text}", flush=True)

        local, stop = run_members(a, out, next_local, serve, jobs, threads, say)
        while comm and len(done_ranks) < size - 1:  # the others finish their members; keep answering them
            serve(stop)
            time.sleep(0.05)
        status.update(local)
        status.update(remote)
        stop = stop or any(s == "interrupted" for s in status.values())
        rows = collect(scan, out, status)
        write_h5(scan, out, rows)
        if not a.no_plot and not stop:
            plot(scan, out)
        else:
            remove_plots(out)
        if not a.quiet:
            wrote = [f for f in ("summary.csv", "scan.h5", "r_cc_grid.png", "sensitivity.png")
                     if os.path.isfile(os.path.join(out, f))]
            print(f"{PROG}: wrote {', '.join(os.path.join(out, f) for f in wrote)} ({time.time() - t0:.1f} s)",
                  flush=True)
        warned = [r["id"] for r in rows if r.get("warnings") not in ("", 0)]
        if warned:
            print(f"{PROG}: warning: {len(warned)} member(s) ended with warnings (unresolved steps, or results "
                  f"outside the model; summary.csv column warnings, members/<id>/summary.json): {' '.join(warned[:10])}"
                  f"{' ...' if len(warned) > 10 else ''}", file=sys.stderr)
        spreading = [r["id"] for r in rows if isinstance(r.get("r_cc_growth_last_tenth"), float)
                     and r["r_cc_growth_last_tenth"] >= 0.01]
        if spreading and not a.quiet:
            print(f"{PROG}: note: {len(spreading)} member(s) still spreading at their end (r_cc grew 1% or more over "
                  f"the last tenth of the run; summary.csv column r_cc_growth_last_tenth): {' '.join(spreading[:10])}"
                  f"{' ...' if len(spreading) > 10 else ''}", flush=True)
        cut = [r["id"] for r in rows if r.get("early_window_cut_at_s") not in ("", None)]
        if cut and not a.quiet:
            print(f"{PROG}: note: {len(cut)} member(s) end inside the early window, so their early_exponent is "
                  f"fitted to part of it (summary.csv column early_window_cut_at_s): {' '.join(cut[:10])}"
                  f"{' ...' if len(cut) > 10 else ''}", flush=True)
        if stop:
            print(f"{PROG}: stopped; run the same command again to finish the missing members", file=sys.stderr)
            rc = 130
        else:
            failed = sorted(mid for mid, s in status.items() if s.startswith("failed"))
            if failed:
                print(f"{PROG}: {len(failed)} member(s) failed: "
                      + ", ".join(f"{mid} ({status[mid][len('failed ('):-1]})" for mid in failed[:10])
                      + (" ..." if len(failed) > 10 else "")
                      + f"; why: {os.path.join(out, 'members', '<id>', 'spread.log')}", file=sys.stderr)
            numerical = any(status[mid] == "failed (numerical)" for mid in failed)
            rc = 3 if numerical else (1 if failed else 0)
        return comm.bcast(rc, root=0) if comm else rc

    # Ranks 1 .. P-1: ask rank 0 for one member at a time.
    threads = a.threads or max(1, per_rank_cores // jobs)

    def next_remote():
        comm.send(None, dest=0, tag=TAG_REQUEST)
        return comm.recv(source=0, tag=TAG_MEMBER)

    def say(text):
        if not a.quiet:
            print(f"{prefix}{text}", flush=True)

    local, stop = run_members(a, out, next_remote, lambda stop: None, jobs, threads, say)
    files = {} if shared else member_files(out, local)
    comm.send({"status": local, "files": files}, dest=0, tag=TAG_DONE)
    return comm.bcast(None, root=0)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:  # Ctrl-C before the members run (while they are checked): nothing was started
        print(f"{PROG}: stopped before any member ran; run the same command again", file=sys.stderr)
        sys.exit(130)
