"""The client side of lsf_batch (scripts/lsf_batch): the bags and their chunks, the preparation of
each bag's folder by `bag_runner --prepare`, the tasks, the progress line, the merge of the
chunks' rows and the table. Nothing here runs on the workers (the task itself is in lsf_batch,
which Dask sends by value)."""

import glob
import os
import sys
import time

CHUNK_DIR = ".chunks"  # DIR/<name>/.chunks/<chunk>.csv: the rows of each task


def expand_bags(patterns):
    """The bags named or matched, in order, each once; patterns matching nothing are returned."""
    bags, unmatched = [], []
    for pattern in patterns:
        matches = sorted(glob.glob(pattern)) if glob.has_magic(pattern) else [pattern]
        if not matches:
            unmatched.append(pattern)
        for path in matches:
            if os.path.abspath(path) not in [os.path.abspath(b) for b in bags]:
                bags.append(path)
    return bags, unmatched


def bag_name(path):
    base = os.path.basename(path)
    return base[:-4] if base.endswith(".bag") else base


def chunks_of(path, chunk):
    """[(start, end)] in seconds after the bag's start (None = open end); one whole chunk when not
    chunking or when the bag cannot be read here (bag_runner then names the problem)."""
    if chunk <= 0:
        return [(None, None)]
    try:
        import rosbag
        with rosbag.Bag(path) as bag:
            duration = bag.get_end_time() - bag.get_start_time()
    except Exception:  # unreadable here: one task, whose bag_runner says why
        return [(None, None)]
    count = max(1, int(duration // chunk) + 1)
    return [(None if k == 0 else k * chunk, None if k == count - 1 else (k + 1) * chunk)
            for k in range(count)]


def chunk_csv(out_dir, start, end):
    label = "whole" if start is None and end is None else "%012.3f" % (start or 0.0)
    return os.path.join(out_dir, CHUNK_DIR, label + ".csv")


def chunk_done(csv_path):
    """A task is done when its rows exist and none failed."""
    if not os.path.exists(csv_path):
        return False
    with open(csv_path) as f:
        return all(line.split(",")[1] != "failed" for line in list(f)[1:] if "," in line)


def merge_rows(out_dir, csv_paths):
    """DIR/<name>/frames.csv: the chunks' rows by stamp (sec, nsec); counts by status."""
    header, rows = None, {}
    for path in csv_paths:
        if not os.path.exists(path):
            continue
        with open(path) as f:
            lines = f.read().splitlines()
        if not lines:
            continue
        header = lines[0]
        for line in lines[1:]:
            sec, _, nsec = line.split(",")[0].partition(".")
            rows[(int(sec), int(nsec or 0))] = line
    counts = {"ok": 0, "skipped": 0, "failed": 0}
    if header is None:
        return counts
    for line in rows.values():
        status = line.split(",")[1]
        counts[status] = counts.get(status, 0) + 1
    tmp = os.path.join(out_dir, "frames.csv.tmp%d" % os.getpid())
    with open(tmp, "w") as f:
        f.write("\n".join([header] + [rows[k] for k in sorted(rows)]) + "\n")
    os.replace(tmp, os.path.join(out_dir, "frames.csv"))
    return counts


class Progress:
    def __init__(self, total):
        self.total, self.done, self.start = total, 0, time.time()
        self.tty = sys.stderr.isatty()

    def step(self, note):
        self.done += 1
        elapsed = time.time() - self.start
        eta = elapsed / self.done * (self.total - self.done)
        bar = "=" * (30 * self.done // max(self.total, 1))
        line = "[%-30s] %d/%d tasks  %s  ETA %.0f s" % (bar, self.done, self.total, note, eta)
        sys.stderr.write(("\r" + line + "\033[K") if self.tty else line + "\n")
        sys.stderr.flush()

    def finish(self):
        if self.tty:
            sys.stderr.write("\n")


def chunks(args, bags):
    """The chunks [(start, end)] of every bag; exits (status 2) when they are more than
    --max-tasks."""
    out = [chunks_of(bag, args.chunk) for bag in bags]
    count = sum(len(c) for c in out)
    if count > args.max_tasks:
        print("lsf_batch: %d tasks (--chunk %g over %d bags) is more than --max-tasks %d: use a "
              "larger --chunk" % (count, args.chunk, len(bags), args.max_tasks), file=sys.stderr)
        sys.exit(2)
    return out


def prepare_command(runner, bag, out_dir, args):
    """bag_runner --prepare on one bag's folder: inputs readable, outputs apart from them, the
    manifest matching (or --force: the folder started over), leftovers of killed runs removed."""
    return [runner, "--bag", os.path.abspath(bag), "--out", os.path.abspath(out_dir),
            "--prepare"] + (["--force"] if args.force else []) + args.passed


def prepare_errors(result):
    """The error lines of a --prepare run (a run_bag_runner result), none when the bag may run."""
    if result["status"] == 0 and not result.get("stopped"):
        return []
    lines = [line.strip() for line in result["stderr"].splitlines() if line.strip()]
    return [line for line in lines if "error" in line] or lines[:1] or [
        "bag_runner --prepare exited with status %s %s" % (result["status"], result.get("stopped"))]


def plan(args, bags, names, runner, chunk_lists, errors):
    """The tasks [(bag index, csv path, command)] of the bags without errors (prepared)."""
    tasks = []
    for i, bag in enumerate(bags):
        if errors[i]:
            continue
        out_dir = os.path.join(args.out, names[i])
        os.makedirs(os.path.join(out_dir, CHUNK_DIR), exist_ok=True)
        # No task of this bag runs now: temporary files left in .chunks are a killed run's.
        stale = glob.glob(os.path.join(out_dir, CHUNK_DIR, ".*.tmp"))
        for old in stale + (glob.glob(os.path.join(out_dir, CHUNK_DIR, "*.csv*"))
                            if args.force else []):
            os.remove(old)
        for start, end in chunk_lists[i]:
            csv_path = chunk_csv(out_dir, start, end)
            command = [runner, "--bag", os.path.abspath(bag), "--out", os.path.abspath(out_dir),
                       "--frames-csv", os.path.abspath(csv_path), "--resume",
                       "--allow-empty"] + args.passed
            if start is not None:
                command += ["--start", repr(start)]
            if end is not None:
                command += ["--end", repr(end)]
            tasks.append((i, csv_path, command))
    return tasks


def report(args, bags, names, tasks, errors, seconds, wall, unmatched):
    failed_bags = 0
    print("\n%-32s %6s %8s %7s %8s %9s" % ("bag", "ok", "skipped", "failed", "task s", "frames/s"))
    total_ok = 0
    for i, bag in enumerate(bags):
        out_dir = os.path.join(args.out, names[i])
        counts = merge_rows(out_dir, [t[1] for t in tasks if t[0] == i])
        total_ok += counts["ok"]
        rate = counts["ok"] / seconds[i] if seconds[i] > 0 else 0.0
        print("%-32s %6d %8d %7d %8.1f %9.2f" % (names[i][:32], counts["ok"], counts["skipped"],
                                                 counts["failed"], seconds[i], rate))
        if counts["failed"] or errors[i]:
            failed_bags += 1
            for line in sorted(set(errors[i])) or ["%d image sets failed" % counts["failed"]]:
                print("lsf_batch: %s: %s" % (bag, line), file=sys.stderr)
    print("%d frames in %.1f s: %.2f frames/s" % (total_ok, wall, total_ok / wall if wall else 0))
    for pattern in unmatched:
        print("lsf_batch: no bag matches %s" % pattern, file=sys.stderr)
    return 1 if failed_bags or unmatched else 0
