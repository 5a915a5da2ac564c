#!/usr/bin/env python3
"""Every command of the README's and docs/*.md's shell blocks runs as written (issue 48).

Reads each ```sh / ```bash / ```console / ```shell block of README.md and docs/*.md, takes the
lines that run mfr (`mfr`, `build/mfr`, `./build/mfr`, after optional VAR=value words) or a
simple `python3` snippet, joins `\\` continuations, and runs each one with bash in a scratch copy
of the checkout (build/mfr and build/python there point at the build under test; ../shared is
the checkout's ../shared where one exists). The blocks run in order (README.md, then docs/ by
name) in one scratch folder whose out/ is emptied before each doc, so a command may read what an
earlier one of its doc wrote; a command that already ran is not run again, its outputs copied in
(`mkdir` lines run too). A command fails
when it exits non-zero or times out, when a compare prints a failed run, or when it leaves a
file outside out/. Markers (docs/DOC_TESTS.md) in an HTML comment on the lines just above a block:

  <!-- doc-test: skip REASON -->                  the block is not run (the reason is printed)
  <!-- doc-test: --width 128 --height 128 ... --> these options are set on each mfr command of
                                                  the block whose `mfr SUB --help` lists them:
                                                  the value replaced where the command has the
                                                  option, else appended

A command whose marker sets a size (--width, --height, --budget, --samples, --sample-counts) still
has its byte budgets checked at the stated size: `mfr info SCENE --methods LIST` at the command's
own options (hybrid where compare lists it, the largest sample count) must give each method a
minimum budget no larger than the smallest of the command's budgets.

Skipped with a message: GL commands (--engine gl, mfr view) without a GL context, commands that
read ../shared/ when it is absent, `build/python` lines without the module, and lines with a `...`
placeholder. Under CI=true a GL command without a GL context (the engine built) is a failure. Exit status: 0 all ran, 1 a command failed, 77 nothing ran.
"""
import argparse
import json
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

FENCE_LANGS = {"sh", "bash", "console", "shell"}
MARKER = re.compile(r"<!--\s*doc-test:\s*(.*?)\s*-->")
ASSIGN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*=")
MFR_WORDS = {"mfr", "build/mfr", "./build/mfr"}
BUDGET_UNITS = {"B": 1, "KB": 1 << 10, "MB": 1 << 20, "GB": 1 << 30}


def split_words(line):
    """Shell words of LINE with their quotes kept, and the comment dropped."""
    words, cur, quote, i = [], "", None, 0
    while i < len(line):
        c = line[i]
        if quote:
            cur += c
            if c == "\\" and quote == '"' and i + 1 < len(line):
                cur += line[i + 1]
                i += 1
            elif c == quote:
                quote = None
        elif c in "'\"":
            quote = c
            cur += c
        elif c == "\\" and i + 1 < len(line):
            cur += c + line[i + 1]
            i += 1
        elif c.isspace():
            if cur:
                words.append(cur)
                cur = ""
        elif c == "#" and not cur:
            break
        else:
            cur += c
        i += 1
    if cur:
        words.append(cur)
    return words


def unquote(word):
    if len(word) >= 2 and word[0] == word[-1] and word[0] in "'\"":
        return word[1:-1]
    return word


class Block:
    def __init__(self, path, line, lang, marker, marker_line):
        self.path, self.line, self.lang = path, line, lang
        self.marker, self.marker_line = marker, marker_line
        self.lines = []  # (line number, text) after joining continuations


def read_blocks(path):
    blocks, marker, marker_line, cur, pending = [], None, 0, None, None
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for n, text in enumerate(lines, 1):
        stripped = text.strip()
        if cur is None:
            m = MARKER.fullmatch(stripped)  # a marker is a line of its own
            if m:
                marker, marker_line = m.group(1), n
                continue
            if stripped.startswith("```"):
                lang = stripped[3:].strip()
                cur = Block(path, n, lang, marker, marker_line)
                marker = None
                continue
            if stripped:  # a marker belongs to the block right below it (blank lines allowed)
                if marker is not None:
                    raise SystemExit(f"{path}:{marker_line}: doc-test marker not followed by a code block")
            continue
        if stripped.startswith("```"):
            if cur.lang in FENCE_LANGS:
                blocks.append(cur)
            cur, pending = None, None
            continue
        if pending is not None:
            pending = (pending[0], pending[1] + " " + text.strip())
        else:
            pending = (n, text.strip())
        if pending[1].endswith("\\") and not pending[1].endswith("\\\\"):
            pending = (pending[0], pending[1][:-1].rstrip())
            continue
        cur.lines.append(pending)
        pending = None
    if marker is not None:
        raise SystemExit(f"{path}:{marker_line}: doc-test marker not followed by a code block")
    return blocks


def parse_marker_options(text):
    words = split_words(text)
    opts, i = [], 0
    while i < len(words):
        w = words[i]
        if not w.startswith("--"):
            raise SystemExit(f"doc-test marker: expected --option, got {w!r} in {text!r}")
        if "=" in w:
            name, value = w.split("=", 1)
            opts.append((name, value))
        elif i + 1 < len(words) and not words[i + 1].startswith("--"):
            opts.append((w, words[i + 1]))
            i += 1
        else:
            opts.append((w, None))
        i += 1
    return opts


class Help:
    """Options of `mfr SUB --help`: every name of each option and whether it takes a value."""

    cache = {}

    def __init__(self, mfr, sub):
        out = subprocess.run([mfr, sub, "--help"], capture_output=True, text=True).stdout
        self.names = {}  # name -> (canonical long name, takes a value)
        for line in out.split("\n"):
            m = re.match(r"^\s{2}(-[-A-Za-z0-9,]+)( ([A-Z]+)\b)?", line)
            if not m:
                continue
            names = m.group(1).split(",")
            canonical = next((x for x in names if x.startswith("--")), names[0])
            takes = m.group(3) is not None and m.group(3) not in ("REQUIRED",)
            for name in names:
                self.names[name] = (canonical, takes)

    @classmethod
    def of(cls, mfr, sub):
        if sub not in cls.cache:
            cls.cache[sub] = Help(mfr, sub)
        return cls.cache[sub]


class Command:
    def __init__(self, words, mfr_index):
        self.words = words
        self.mfr_index = mfr_index  # index of the mfr word (after VAR=value words)
        self.sub = words[mfr_index + 1] if mfr_index + 1 < len(words) else ""

    def parse(self, helpinfo):
        """[(canonical, value or None, index of the option word)], positionals [(index, word)]."""
        opts, positionals = [], []
        i = self.mfr_index + 2
        while i < len(self.words):
            w = self.words[i]
            if w.startswith("-") and len(w) > 1:
                name, value = (w.split("=", 1) + [None])[:2] if w.startswith("--") else (w, None)
                canonical, takes = helpinfo.names.get(name, (name, False))
                if takes and value is None and i + 1 < len(self.words):
                    value = self.words[i + 1]
                    opts.append((canonical, value, i, 2))
                    i += 2
                    continue
                opts.append((canonical, value, i, 1))
            else:
                positionals.append((i, w))
            i += 1
        return opts, positionals

    def set_option(self, helpinfo, name, value):
        canonical = helpinfo.names[name][0]
        opts, _ = self.parse(helpinfo)
        found = [o for o in opts if o[0] == canonical]
        if found:
            _, _, index, count = found[-1]
            if value is None:
                return
            if count == 2:
                self.words[index + 1] = value
            else:
                self.words[index] = f"{self.words[index].split('=', 1)[0]}={value}"
        else:
            self.words += [name] + ([value] if value is not None else [])

    def text(self):
        return " ".join(self.words)


def budgets_in_bytes(values):
    out = []
    for v in ",".join(values).split(","):
        m = re.fullmatch(r"\s*([0-9.]+)\s*(B|KB|MB|GB)\s*", unquote(v), re.IGNORECASE)
        if m:
            out.append((unquote(v).strip(), int(float(m.group(1)) * BUDGET_UNITS[m.group(2).upper()])))
    return out


def stated_size_checks(cmd, helpinfo, mfr):
    """`mfr info` command lines that give the methods' minimum budgets at the stated size."""
    if cmd.sub not in ("render", "compare"):
        return []
    opts, positionals = cmd.parse(helpinfo)
    budgets = budgets_in_bytes([v for n, v, _, _ in opts if n == "--budget" and v])
    if not budgets or not positionals:
        return []
    methods = [v for n, v, _, _ in opts if n in ("--methods", "--method") and v]
    if not methods:
        return []  # the default list: too long to check here
    info_help = Help.of(mfr, "info")
    counts = [v for n, v, _, _ in opts if n == "--sample-counts" and v]
    carried = []
    for name, value, _, _ in opts:
        if name in ("--budget", "--methods", "--method", "--composite", "--json", "--quiet"):
            continue
        if name == "--samples" and counts:
            continue
        if name in info_help.names and info_help.names[name][1] == (value is not None):
            carried += [name] + ([value] if value is not None else [])
    composites = [v for n, v, _, _ in opts if n == "--composite" and v]
    if cmd.sub == "compare":
        rules = unquote(composites[-1]).split(",") if composites else ["kbuffer", "hybrid"]
        if "hybrid" in rules:
            rules = ["hybrid"]  # its tail words make its minimum the larger one
    else:
        rules = [unquote(composites[-1])] if composites else [None]
    # at the largest sample count of the command: the minimum grows with the samples
    own = [unquote(v) for n, v, _, _ in opts if n == "--samples" and v]
    listed = [int(c) for c in unquote(counts[-1]).split(",") if c.isdigit()] if counts else []
    largest = max([int(x) for x in own if x.isdigit()] + listed + [1])
    sample = ["--samples", str(largest)] if counts and largest > 1 else []
    checks = []
    for rule in rules:
        words = cmd.words[: cmd.mfr_index + 1] + ["info", positionals[0][1]] + carried + sample
        words += ["--methods", methods[-1], "--json", "-q"]
        if rule:
            words += ["--composite", rule]
        label = ", ".join(x for x in [rule, " ".join(sample)] if x)
        checks.append((" ".join(words), budgets, label))
    return checks


def out_files(folder):
    """{path under out/: (size, mtime)} of the files of FOLDER/out."""
    found, top = {}, os.path.join(folder, "out")
    for base, _, files in os.walk(top):
        for name in files:
            path = os.path.join(base, name)
            st = os.lstat(path)
            found[os.path.relpath(path, top)] = (st.st_size, st.st_mtime_ns)
    return found


def snapshot(folder):
    """{path: (size, mtime)} of every file of FOLDER outside out/ (and the shared link)."""
    found = {}
    for base, dirs, files in os.walk(folder):
        rel = os.path.relpath(base, folder)
        if rel == ".":
            dirs[:] = [d for d in dirs if d not in ("out", "shared")]
        for name in files + [d for d in dirs if os.path.islink(os.path.join(base, d))]:
            st = os.lstat(os.path.join(base, name))
            found[os.path.normpath(os.path.join(rel, name))] = (st.st_size, st.st_mtime_ns)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mfr", help="the mfr binary under test")
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    ap.add_argument("--only", action="append", default=[], help="only this doc (repeatable)")
    ap.add_argument("--timeout", type=float, default=150, help="seconds per command (default 150)")
    ap.add_argument("--list", action="store_true", help="print the commands as they would run")
    ap.add_argument("--keep", action="store_true", help="keep the scratch folder")
    ap.add_argument("--gl-built", choices=["yes", "no"], default="yes",
                    help="no: the build has no GL engine, its commands are skipped even under CI=true")
    ap.add_argument("--python", help="the interpreter the module was built for: `python3` in the commands")
    args = ap.parse_args()
    root = os.path.realpath(args.root)
    mfr = os.path.realpath(args.mfr)
    build = os.path.dirname(mfr)
    ci = os.environ.get("CI") == "true"

    docs = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    if args.only:
        docs = [d for d in docs if os.path.relpath(d, root) in args.only or os.path.basename(d) in args.only]

    tmp = tempfile.mkdtemp(prefix="mfr-doc-commands-")
    work = os.path.join(tmp, "checkout")
    ignore = shutil.ignore_patterns(".git", "out", "build*", "bench-results", "gpu-check-results")
    shutil.copytree(root, work, ignore=ignore, symlinks=True)
    os.makedirs(os.path.join(work, "build"))
    os.symlink(mfr, os.path.join(work, "build", "mfr"))
    if os.path.isdir(os.path.join(build, "python")):
        os.symlink(os.path.join(build, "python"), os.path.join(work, "build", "python"))
    shared = os.path.realpath(os.path.join(root, "..", "shared"))
    have_shared = os.path.isdir(shared)
    if have_shared:
        os.symlink(shared, os.path.join(tmp, "shared"))
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    env["PATH"] = os.path.join(work, "build") + os.pathsep + env.get("PATH", "")
    if args.python:
        os.makedirs(os.path.join(tmp, "bin"))
        for name in ("python3", "python"):
            os.symlink(os.path.realpath(shutil.which(args.python) or args.python), os.path.join(tmp, "bin", name))
        env["PATH"] = os.path.join(tmp, "bin") + os.pathsep + env["PATH"]

    gl_state = None  # None: not probed; else (ok, why)

    def gl_available():
        nonlocal gl_state
        if gl_state is None:
            p = subprocess.run([mfr, "info", "procedural:layers", "--engine", "gl", "--width", "8", "--height", "8"],
                               capture_output=True, text=True, cwd=tmp)
            gl_state = (p.returncode == 0, (p.stderr.strip().split("\n") or [""])[-1])
        return gl_state

    ran = failed = skipped = 0
    failures, seen = [], {}  # seen: script -> (file:line, {path under out/: copy of it})
    cache = os.path.join(tmp, "outputs")
    started = time.time()
    for doc in docs:
        rel = os.path.relpath(doc, root)
        shutil.rmtree(os.path.join(work, "out"), ignore_errors=True)  # each doc starts afresh
        for block in read_blocks(doc):
            marker_opts = []
            if block.marker is not None:
                if block.marker.startswith("skip"):
                    reason = block.marker[4:].strip() or "(no reason given)"
                    print(f"skip  {rel}:{block.line}: block: {reason}")
                    skipped += 1
                    continue
                marker_opts = parse_marker_options(block.marker)
            prelude = []
            for n, text in block.lines:
                words = split_words(text)
                if not words:
                    continue
                k = 0
                while k < len(words) and ASSIGN.match(words[k]):
                    k += 1
                if k == len(words):  # S='...': kept for the block's later commands
                    prelude.append(" ".join(words))
                    continue
                where = f"{rel}:{n}"
                is_mfr = words[k] in MFR_WORDS
                is_python = words[k] in ("python3", "python")
                if words[k] == "mkdir":  # mkdir -p out: run, not counted
                    subprocess.run(["bash", "-c", " ".join(words)], cwd=work, env=env, check=False)
                    continue
                if not (is_mfr or is_python):
                    continue  # make, cmake, scripts/...: not run here
                if "..." in words:
                    print(f"skip  {where}: placeholder '...': {text}")
                    skipped += 1
                    continue
                cmd = Command(words, k)
                checks = []
                if is_mfr:
                    helpinfo = Help.of(mfr, cmd.sub)
                    sizes = {"--width", "--height", "--budget", "--budgets", "--samples", "--sample-counts"}
                    reduced = any(name in sizes for name, _ in marker_opts)
                    checks = stated_size_checks(cmd, helpinfo, mfr) if reduced else []
                    for name, value in marker_opts:
                        if name in helpinfo.names:
                            cmd.set_option(helpinfo, name, value)
                line = cmd.text()
                is_gl = is_mfr and (cmd.sub == "view" or re.search(r"--engine(=|\s+)['\"]?gl\b", line))
                if is_gl:
                    ok, why = gl_available() if args.gl_built == "yes" else (False, "built without the GL engine")
                    if not ok:
                        if ci and args.gl_built == "yes":
                            failures.append((where, line, f"no GL context under CI=true: {why}"))
                            failed += 1
                        else:
                            print(f"skip  {where}: no GL context ({why}): {line}")
                            skipped += 1
                        continue
                if "build/python" in line and not os.path.isdir(os.path.join(build, "python")):
                    print(f"skip  {where}: the Python module is not built ({build}/python): {line}")
                    skipped += 1
                    continue
                if "../shared/" in line and not have_shared:
                    print(f"skip  {where}: ../shared is absent: {line}")
                    skipped += 1
                    continue
                script = "\n".join(prelude + [line])
                if args.list:
                    print(f"run   {where}: {line}")
                    for check, _, _ in checks:
                        print(f"check {where}: {check}")
                    continue
                if script in seen:  # its outputs copied in: what a later command of the doc reads
                    first, outputs = seen[script]
                    for path, copy in outputs.items():
                        os.makedirs(os.path.dirname(os.path.join(work, "out", path)), exist_ok=True)
                        shutil.copy2(copy, os.path.join(work, "out", path))
                    print(f"same  {where}: as {first}")
                    continue
                problems = []
                for check, budgets, rule in checks:
                    p = subprocess.run(["bash", "-c", "\n".join(prelude + [check])], capture_output=True,
                                       text=True, cwd=work, env=env, timeout=args.timeout)
                    if p.returncode != 0:
                        problems.append(f"budget check `{check}` failed: {p.stderr.strip()}")
                        continue
                    info = json.loads(p.stdout)
                    for view in info["views"]:
                        for method in view["budgets"]["methods"]:
                            for spelled, size in budgets:
                                if method["minimum_bytes"] and size < method["minimum_bytes"]:
                                    problems.append(
                                        f"at the stated size, {method['method']}"
                                        f"{' (' + rule + ')' if rule else ''} needs at least "
                                        f"{method['minimum_bytes']} B: budget {spelled} is too small")
                before, out_before = snapshot(work), out_files(work)
                t0 = time.time()
                try:
                    p = subprocess.run(["bash", "-c", script], capture_output=True, text=True, cwd=work, env=env,
                                       timeout=args.timeout)
                    rc, out, err = p.returncode, p.stdout, p.stderr
                except subprocess.TimeoutExpired as e:
                    rc, out, err = "timeout", "", f"timed out after {args.timeout:.0f} s"
                seconds = time.time() - t0
                if rc != 0:
                    problems.append(f"exit {rc}: {err.strip() or out.strip()[-2000:]}")
                if is_mfr and cmd.sub == "compare":
                    problems += [f"a run failed: {l.strip()}" for l in out.split("\n") if " failed: " in l]
                outputs = {}
                for path, state in out_files(work).items():
                    if out_before.get(path) != state:
                        outputs[path] = os.path.join(cache, str(len(seen)), path)
                        os.makedirs(os.path.dirname(outputs[path]), exist_ok=True)
                        shutil.copy2(os.path.join(work, "out", path), outputs[path])
                seen[script] = (where, outputs)
                outside = sorted(p for p, state in snapshot(work).items() if before.get(p) != state)
                if outside:
                    problems.append("wrote outside out/: " + ", ".join(outside[:8]))
                ran += 1
                if problems:
                    failed += 1
                    failures.append((where, line, "\n    ".join(problems)))
                    print(f"FAIL  {where} ({seconds:.1f} s): {line}")
                else:
                    print(f"ok    {where} ({seconds:.1f} s): {line}")
                sys.stdout.flush()
    if args.keep:
        print(f"scratch folder kept: {tmp}")
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    for where, line, why in failures:
        print(f"\nFAIL {where}: {line}\n    {why}")
    print(f"\n{ran} commands ran, {failed} failed, {skipped} skipped, {time.time() - started:.0f} s")
    if failed:
        return 1
    return 0 if ran or args.list else 77


if __name__ == "__main__":
    sys.exit(main())
