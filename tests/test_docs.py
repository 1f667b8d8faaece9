#!/usr/bin/python3
"""The docs checked against the code (issue 28, "Docs checked by tests").

  FDEM_BINARY=build/fdem /usr/bin/python3 tests/test_docs.py [-v]     (ctest: `docs`, label unit)
  FDEM_BINARY=build/fdem /usr/bin/python3 tests/test_docs.py --update  (rewrite the `check`
                                                                         figures of the file)

1. Commands. Every shell command in a code block (fenced, or indented by four spaces) of
   README.md and docs/*.md that calls fdem, tools/fdem-plot, tools/fdem-wave, mpirun or
   make is run in a cheap form or checked, and a failure names the doc, the line and the
   command:
   - optional parts written `[...]` are left out, `...` dropped, a trailing `# comment`
     ignored, `\\` continuations joined, `a && b` taken apart;
   - `fdem ... CASE.toml` (and `case.toml`) runs on a small case instead
     (tests/data/cases/column_small.toml with `time.end`), in a temporary folder;
     `OUT/NAME.ckpt` and `old.ckpt` are that run's checkpoint;
   - `fdem run` of the small case runs for real, shortened: `--set time.end=20` (20
     steps; 40 for a `--restart`, which must go past its checkpoint), `--set
     output.dir=` a temporary folder, `--device cpu` and `--quiet`; `fdem run` of a case
     of cases/ is `fdem check` of the same case and `--set`s instead (the full-size
     cases take minutes); `fdem check`, `devices` and `--version` run as written;
   - what needs a GPU (`--device gpu`) or several ranks (`mpirun`) and `fdem bench` is
     checked for its options only: each must be one that `fdem --help` lists for that
     command;
   - `tools/fdem-plot field|history|compare` run on the small run's output (OUT.exo,
     OUT_history.nc, a_history.nc ...); the other fdem-plot and every fdem-wave command
     (they need fracture, platen or probe output) go through the tool's own argument
     parser only;
   - `make TARGET`: the Makefile must have the target;
   - the commands of cases/*/README.md too, more cheaply: every `fdem run` there (GPU or
     not) is `fdem check` of its case and --sets, the tools' arguments are parsed, and
     shell loops (a line with a `$variable`) are left out.
2. Figures. A number in README.md, docs/*.md or cases/*/README.md followed by
   `<!-- figure: KEY -->` must be the value of KEY in tests/data/doc_figures.json, and
   every key there must be quoted somewhere. A key with a `check` entry is recomputed:
   `fdem check CASE [--set ...]` and the field named (TRI3, CE4, nodes, stable dt, case
   dt, steps, or a material's TRI3); the others (bench rows, GPU runs) carry the command
   and machine that made them in `from`.

Meshes made from .geo files are cached in $FDEM_DOCS_MESH_CACHE (ctest: the build
tree's docs-mesh-cache), so only the first run meshes (blasting and brazilian: about a
minute on 2 cores, the other cases a minute more); after that the whole test takes
30-50 s.
"""

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
sys.path.insert(0, os.path.join(REPO, "python"))

FIGURES = os.path.join(REPO, "tests", "data", "doc_figures.json")
SMALL_CASE = os.path.join(REPO, "tests", "data", "cases", "column_small.toml")
COMMAND_DOCS = ["README.md"] + sorted(
    os.path.join("docs", f) for f in os.listdir(os.path.join(REPO, "docs")) if f.endswith(".md"))
FIGURE_DOCS = COMMAND_DOCS + sorted(
    os.path.join("cases", c, "README.md") for c in os.listdir(os.path.join(REPO, "cases"))
    if os.path.isfile(os.path.join(REPO, "cases", c, "README.md")))
PROGRAMS = ("fdem", "fdemw", "fdem-plot", "fdem-wave", "mpirun", "make")
MARKER = re.compile(r"([-+]?[0-9][0-9,]*(?:\.[0-9]+)?(?:[eE][-+]?[0-9]+)?)(?:\s*[A-Za-z%µ]{0,3})?\s*"
                    r"<!--\s*figure:\s*([A-Za-z0-9_.-]+)\s*-->")


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def fdem_binary():
    path = os.environ.get("FDEM_BINARY") or os.path.join(REPO, "build", "fdem")
    return os.path.abspath(path) if os.path.isfile(path) else None


# ---------------------------------------------------------------------------------------
# Commands of the docs

def code_lines(doc):
    """(line number, text) of the shell lines in the code blocks of `doc`, continuation
    lines joined (the number is the first line's)."""
    out, fenced, fence_lang = [], False, ""
    lines = read(os.path.join(REPO, doc)).split("\n")
    pending, start = "", 0
    for number, line in enumerate(lines, start=1):
        if line.startswith("```"):
            fenced, fence_lang = (not fenced), line[3:].strip()
            continue
        if fenced:
            if fence_lang not in ("", "sh", "bash", "shell", "console"):
                continue
            text = line
        elif line.startswith("    ") and (pending or not line.lstrip().startswith(("-", "|"))):
            text = line[4:]
        else:
            pending = ""
            continue
        if not pending:
            start = number
        if text.rstrip().endswith("\\"):
            pending += text.rstrip()[:-1] + " "
            continue
        out.append((start, (pending + text).strip()))
        pending = ""
    return out


def without_optional(tokens):
    """The tokens with `[...]` groups (nested) and `...` left out."""
    out, depth = [], 0
    for tok in tokens:
        if depth > 0 or (tok.startswith("[") and not tok.startswith("[[")):
            depth += tok.count("[") - tok.count("]")
            continue
        if tok != "...":
            out.append(tok)
    return out


CASE_DOCS = [d for d in FIGURE_DOCS if d.startswith("cases")]


def doc_commands(docs=None):
    """(doc, line, text, tokens) of every command that calls one of PROGRAMS (shell
    loops, whose lines hold a `$variable`, are left out)."""
    found = []
    for doc in docs or COMMAND_DOCS:
        for number, text in code_lines(doc):
            if "$" in text:
                continue
            try:
                tokens = shlex.split(text, comments=True)
            except ValueError:
                continue
            # a && b: each part on its own
            parts, part = [], []
            for tok in tokens:
                if tok in ("&&", ";"):
                    parts.append(part)
                    part = []
                else:
                    part.append(tok)
            parts.append(part)
            for part in parts:
                if part and os.path.basename(part[0]) in PROGRAMS:
                    found.append((doc, number, text, without_optional(part)))
    return found


def usage_options(binary):
    """{command: set of options} from `fdem --help`."""
    text = subprocess.run([binary, "--help"], capture_output=True, text=True).stdout
    options, command = {}, None
    for line in text.split("\n"):
        m = re.search(r"fdem (run|check|devices|bench)\b", line)
        if m:
            command = m.group(1)
        elif not line.startswith(" "):
            command = None
        if command:
            options.setdefault(command, set()).update(re.findall(r"--[a-z][a-z-]*", line))
    return options


class Commands(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = fdem_binary()
        cls.work = tempfile.mkdtemp(prefix="fdem_docs_test.")
        cls.out = os.path.join(cls.work, "out")
        # The small case with an end time (the docs' --set time.end must apply to it).
        text = read(SMALL_CASE)
        text = re.sub(r"(?m)^steps = \d+$", "end = 300.0", text)
        text = text.replace('file = "column_small.msh"', 'file = "%s"' % os.path.join(
            os.path.dirname(SMALL_CASE), "column_small.msh"))
        cls.case = os.path.join(cls.work, "small.toml")
        with open(cls.case, "w", encoding="utf-8") as f:
            f.write(text)
        cls.checkpoint = os.path.join(cls.out, "column.ckpt")
        cls.exo = os.path.join(cls.out, "column.exo")
        cls.history = os.path.join(cls.out, "column_history.nc")
        if cls.binary:
            cls.options = usage_options(cls.binary)
            # One run first, so that checkpoint and output exist for the commands that
            # read them, whatever their order in the docs.
            cls.fdem(["run", cls.case, "--device", "cpu", "--quiet", "--set",
                      f"output.dir={cls.out}", "--set", "time.end=20"], check=True)
            shutil.copy(cls.checkpoint, os.path.join(cls.work, "old.ckpt"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)

    @classmethod
    def fdem(cls, args, check=False):
        env = dict(os.environ)
        env.setdefault("FDEM_MESH_CACHE", os.environ.get("FDEM_DOCS_MESH_CACHE",
                                                         os.path.join(cls.work, "mesh")))
        os.makedirs(env["FDEM_MESH_CACHE"], exist_ok=True)
        proc = subprocess.run([cls.binary] + args, capture_output=True, text=True, cwd=REPO,
                              env=env, timeout=300)
        if check and proc.returncode != 0:
            raise RuntimeError(f"fdem {' '.join(args)}: exit {proc.returncode}\n{proc.stdout}{proc.stderr}")
        return proc

    def substitute(self, tok):
        if tok in ("CASE.toml", "case.toml"):
            return self.case
        if tok == "OUT/NAME.ckpt":
            return self.checkpoint
        if tok == "old.ckpt":
            return os.path.join(self.work, "old.ckpt")
        if tok.startswith("OUT/NAME_") and tok.endswith(".png") or tok.endswith(".png"):
            return os.path.join(self.work, os.path.basename(tok))
        if tok == "OUT.exo":
            return self.exo
        if tok == "OUT_history.nc":
            return self.history
        m = re.match(r"^([ab])_history\.nc(:.*)?$", tok)
        if m:
            return self.history + (m.group(2) or "")
        return tok

    def check_options(self, command, args):
        """Every --option of `args` is one fdem --help lists for `command`."""
        known = self.options.get(command, set())
        bad = [a.split("=")[0] for a in args
               if a.startswith("--") and a.split("=")[0] not in known | {"--help"}]
        return f"options not in `fdem --help` for {command}: {', '.join(bad)}" if bad else None

    def fdem_command(self, tokens, check_only=False):
        """None when the command is fine, else why not. `check_only`: a run is `fdem
        check` of its case and --sets whatever its device (the case READMEs)."""
        mpi = os.path.basename(tokens[0]) == "mpirun"
        if mpi:
            at = next((i for i, t in enumerate(tokens)
                       if os.path.basename(t) in ("fdem", "fdemw")), None)
            if at is None:
                return "mpirun without fdem"
            tokens = tokens[at:]
        if len(tokens) < 2:
            return "fdem without a command"
        command, args = tokens[1], [self.substitute(t) for t in tokens[2:]]
        if command == "--version":
            proc = self.fdem(["--version"])
            return None if proc.returncode == 0 else f"exit {proc.returncode}"
        if command not in self.options:
            return f"unknown command {command!r} (fdem --help lists {', '.join(sorted(self.options))})"
        problem = self.check_options(command, args)
        if problem:
            return problem
        gpu = "gpu" in args[args.index("--device") + 1:args.index("--device") + 2] \
            if "--device" in args else False
        if check_only and command == "run" and not mpi:
            gpu = False
        if mpi or gpu or command == "bench":
            self.action = "options checked (GPU, ranks or bench)"
            return None  # options only: no GPU or ranks here
        if "--help" in args:
            proc = self.fdem([command, "--help"])
            self.action = "run as written (a command's help)"
            return None if proc.returncode == 0 and proc.stdout.strip() else f"exit {proc.returncode}"
        if command == "devices":
            proc = self.fdem(["devices"])
            return None if proc.returncode in (0, 4) else f"exit {proc.returncode}"
        sets = []
        for i, a in enumerate(args):
            if a == "--set" and i + 1 < len(args):
                sets += ["--set", args[i + 1]]
        case = args[0] if args and not args[0].startswith("--") else None
        if case is None:
            return "no case file"
        if command == "check" or case != self.case or check_only:
            # check as written (its own options kept), or a run's case and --sets checked
            keep = args[1:] if command == "check" else sets
            if not case.endswith(".ckpt"):
                keep = keep + ["--set", f"output.dir={os.path.join(self.work, 'o')}"]
            proc = self.fdem(["check", case] + keep)
            self.action = "fdem check" + ("" if command == "check" else " of the run's case and --sets")
            return None if proc.returncode == 0 else \
                f"fdem check (for {command}): exit {proc.returncode}: {(proc.stdout + proc.stderr)[-600:]}"
        # fdem run of the small case, shortened (module docstring).
        restart = "--restart" in args
        keep, i = [], 1
        while i < len(args):
            if args[i] == "--device":
                i += 2
                continue
            # The small case's step is 1 s: a checkpoint interval in it, 5 steps.
            keep.append("output.checkpoint_every=5" if args[i].startswith("output.checkpoint_every=")
                        else args[i])
            i += 1
        # A restart from a named checkpoint file goes to a folder of its own: the small
        # run's folder holds the outputs of later runs, which that checkpoint's run did
        # not write (--restart refuses to append to them).
        out = self.out
        if restart and args.index("--restart") + 1 < len(args) and args[args.index("--restart") + 1].endswith(".ckpt"):
            out = tempfile.mkdtemp(dir=self.work)
        self.action = f"run on the small case, time.end={40 if restart else 20}"
        proc = self.fdem(["run", case] + keep + ["--device", "cpu", "--quiet", "--set",
                                                 f"output.dir={out}", "--set",
                                                 f"time.end={40 if restart else 20}"])
        return None if proc.returncode == 0 else \
            f"exit {proc.returncode}: {(proc.stdout + proc.stderr)[-600:]}"

    def tool_command(self, tokens, check_only=False):
        tool = os.path.basename(tokens[0])
        args = [self.substitute(t) for t in tokens[1:]]
        module = __import__("fdem.plot" if tool == "fdem-plot" else "fdem.wave",
                            fromlist=["parse_args"])
        try:
            module.parse_args(args)
        except SystemExit as exc:
            return f"{tool} refuses its arguments (exit {exc.code})"
        self.action = "arguments parsed"
        if tool == "fdem-plot" and args and not check_only and (
                args[0] in ("history", "compare") or (args[0] == "field" and "--cracks" not in args)):
            proc = subprocess.run([sys.executable, os.path.join(REPO, "tools", tool)] + args,
                                  capture_output=True, text=True, cwd=self.work, timeout=120)
            self.action = "run on the small run's output"
            if proc.returncode != 0:
                return f"exit {proc.returncode}: {(proc.stdout + proc.stderr)[-600:]}"
        return None

    def test_every_command_runs(self):
        self.commands_of(None, 20)

    def test_case_readme_commands(self):
        """The commands of cases/*/README.md: every `fdem run` (GPU or not) is `fdem
        check` of its case and --sets; the Python tools' arguments are parsed."""
        self.commands_of(CASE_DOCS, 30, check_only=True)

    def commands_of(self, docs, at_least, check_only=False):
        if not self.binary:
            self.skipTest("no fdem binary (FDEM_BINARY or build/fdem)")
        commands = doc_commands(docs)
        self.assertGreater(len(commands), at_least, "the extraction finds the docs' commands")
        failures, log = [], []
        for doc, number, text, tokens in commands:
            program = os.path.basename(tokens[0])
            self.action = "run as written"
            if program == "make":
                makefile = read(os.path.join(REPO, "Makefile"))
                missing = [t for t in tokens[1:] if not t.startswith("-") and "=" not in t and
                           not re.search(rf"(?m)^{re.escape(t)}:", makefile)]
                problem = f"no target {', '.join(missing)} in the Makefile" if missing else None
                self.action = "Makefile target found"
            elif program in ("fdem-plot", "fdem-wave"):
                problem = self.tool_command(tokens, check_only)
            else:
                problem = self.fdem_command(tokens, check_only)
            log.append(f"{doc}:{number}: {self.action}: {' '.join(tokens)[:90]}")
            if problem:
                failures.append(f"{doc}:{number}: {text}\n    {problem}")
        print(f"\n{len(commands)} commands of the docs:\n" + "\n".join(log), file=sys.stderr)
        self.assertEqual(failures, [], "\n" + "\n".join(failures))


# ---------------------------------------------------------------------------------------
# Figures

def marked_figures():
    """(doc, line, key, number as written) of every figure marker."""
    out = []
    for doc in FIGURE_DOCS:
        text = read(os.path.join(REPO, doc))
        ends = set()
        for m in MARKER.finditer(text):
            out.append((doc, text.count("\n", 0, m.start()) + 1, m.group(2), m.group(1)))
            ends.add(m.end())
        for m in re.finditer(r"<!--\s*figure:[^>]*-->", text):
            if m.end() not in ends:  # a marker with no number just before it
                out.append((doc, text.count("\n", 0, m.start()) + 1, None, None))
    return out


def check_output(binary, case, sets, cache):
    os.makedirs(cache, exist_ok=True)
    env = dict(os.environ)
    env["FDEM_MESH_CACHE"] = cache
    args = [binary, "check", os.path.join(REPO, case)]
    for s in sets:
        args += ["--set", s]
    args += ["--set", "output.dir=" + os.path.join(cache, "out")]
    proc = subprocess.run(args, capture_output=True, text=True, env=env, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(args)}: exit {proc.returncode}\n{proc.stdout}{proc.stderr}")
    return proc.stdout


def field_of(text, field):
    """A figure out of `fdem check` output, formatted as the docs write it."""
    patterns = {"TRI3": r"^TRI3\s+(\d+)", "nodes": r"^nodes\s+(\d+)", "CE4": r"^CE4\s+(\d+)",
                "steps": r"^steps\s+(\d+)", "stable dt": r"^stable dt\s+(\S+) s",
                "case dt": r"^case dt\s+(\S+) s"}
    m = re.match(r"^material (\S+) TRI3$", field)
    pattern = (rf"^\s+material '{re.escape(m.group(1))}': (\d+) TRI3" if m else patterns[field])
    found = re.search(pattern, text, re.M)
    if not found:
        raise KeyError(f"no {field!r} in the output of fdem check")
    value = found.group(1)
    return f"{int(value):,}" if value.isdigit() else value


class Figures(unittest.TestCase):
    def test_marked_figures_are_the_files(self):
        figures = json.loads(read(FIGURES))
        marks = marked_figures()
        problems = []
        for doc, line, key, number in marks:
            if key is None:
                problems.append(f"{doc}:{line}: a figure marker with no number before it")
            elif key not in figures:
                problems.append(f"{doc}:{line}: figure {key!r} is not in {FIGURES}")
            elif number != figures[key]["value"]:
                problems.append(f"{doc}:{line}: figure {key} reads {number}, "
                                f"{os.path.basename(FIGURES)} has {figures[key]['value']} "
                                f"({figures[key]['from']})")
        used = {key for _, _, key, _ in marks}
        for key in figures:
            if key not in used:
                problems.append(f"{os.path.basename(FIGURES)}: figure {key} is quoted nowhere")
        self.assertEqual(problems, [], "\n" + "\n".join(problems))

    def test_check_figures_are_the_engines(self):
        binary = fdem_binary()
        if not binary:
            self.skipTest("no fdem binary (FDEM_BINARY or build/fdem)")
        figures = json.loads(read(FIGURES))
        cache = os.environ.get("FDEM_DOCS_MESH_CACHE") or tempfile.mkdtemp(prefix="fdem_docs_mesh.")
        outputs, problems = {}, []
        for key, figure in figures.items():
            check = figure.get("check")
            if not check:
                continue
            run = (check["case"], tuple(check.get("set", [])))
            if run not in outputs:
                outputs[run] = check_output(binary, run[0], run[1], cache)
            value = field_of(outputs[run], check["field"])
            if value != figure["value"]:
                problems.append(f"{key}: fdem check {run[0]} gives {check['field']} {value}, "
                                f"the docs {figure['value']} (tests/test_docs.py --update "
                                f"rewrites the file; then the docs)")
        self.assertEqual(problems, [], "\n" + "\n".join(problems))


def update():
    """Rewrite the `check` figures of the figures file from fdem check."""
    binary = fdem_binary()
    figures = json.loads(read(FIGURES))
    cache = os.environ.get("FDEM_DOCS_MESH_CACHE") or tempfile.mkdtemp(prefix="fdem_docs_mesh.")
    outputs = {}
    for key, figure in figures.items():
        check = figure.get("check")
        if check:
            run = (check["case"], tuple(check.get("set", [])))
            if run not in outputs:
                outputs[run] = check_output(binary, run[0], run[1], cache)
            value = field_of(outputs[run], check["field"])
            if value != figure["value"]:
                print(f"{key}: {figure['value']} -> {value}")
                figure["value"] = value
    with open(FIGURES, "w", encoding="utf-8") as f:
        json.dump(figures, f, indent=2, ensure_ascii=False)
        f.write("\n")


if __name__ == "__main__":
    if "--update" in sys.argv:
        update()
    else:
        unittest.main()
