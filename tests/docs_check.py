#!/usr/bin/python3
"""docs-check: the user-facing documentation still matches the code.

Usage: /usr/bin/python3 tests/docs_check.py [PHGMG_BINARY]   (from the repository root)

Fails (exit 1, one line per finding) when
  - a public function (a PHGMG_DEF declaration in the header's declaration
    half) is missing from the INDEX section of the manual at the top of
    phgmg.h, or the index names a function that is not declared, or its
    count of functions is not the number declared;
  - a configuration macro the header lets the user define (an #ifndef
    default or a defined() switch) is not listed in the manual's section 9;
  - `phgmg --help` (build/phgmg by default) does not name an option that
    examples/phgmg_cli.c's parser accepts;
  - the first C block of README.md does not compile (C99, warnings as errors)
    or does not run with exit status 0;
  - phgmg_reduce_opts_default() disagrees with the defaults in the manual's
    table (3.2) or with the defaults `phgmg --help` states for --rn,
    --deim-tol and --hyper-tol;
  - a renamed option of the newest revision history entry's table
    (old -> new) compiles under its old name, or not under its new one;
  - a tracked file name starts with '-';
  - the private functions declared in phgmg.h's >>linalg (prototypes) are not
    exactly those defined in >>linalg (implementation), with the same
    signatures, in the same order;
  - README.md, phgmg.h or the Makefile mention an issue number, a "session",
    or a document outside the repository (the notes files by name).
"""
import os, re, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CC = os.environ.get("CC", "cc")
problems = []


def read(path):
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        return f.read()


def check_index(header):
    lines = header.split("\n")
    impl = next(i for i, l in enumerate(lines) if l.startswith(("#ifdef PHGMG_IMPLEMENTATION", "#if defined(PHGMG_IMPLEMENTATION)")))
    declared = set()
    for l in lines[:impl]:
        m = re.match(r"PHGMG_DEF\b.*?\b(phgmg_[A-Za-z0-9_]+)\s*\(", l)
        if m:
            declared.add(m.group(1))
    top = header[: header.index("*/")]
    if "INDEX OF PUBLIC FUNCTIONS" not in top:
        problems.append("phgmg.h: the manual has no INDEX OF PUBLIC FUNCTIONS section")
        return
    index = top[top.index("INDEX OF PUBLIC FUNCTIONS"):]
    named = set(re.findall(r"\bphgmg_[A-Za-z0-9_]+", index))
    for f in sorted(declared - named):
        problems.append("phgmg.h: public function %s is missing from the manual's index" % f)
    for f in sorted(named - declared):
        problems.append("phgmg.h: the manual's index names %s, which is not a public function" % f)
    sec9 = top[top.find("9. CONFIGURATION MACROS"):top.find("10. INDEX")]
    overridable = set(re.findall(r"#ifndef (PHGMG_[A-Z0-9_]+)\s*\n\s*#\s*define \1\b", header))
    overridable |= set(re.findall(r"defined\((PHGMG_[A-Z0-9]+(?:_[A-Z0-9]+)*)\)", header))
    overridable -= {"PHGMG_H_INCLUDED", "PHGMG_IMPLEMENTATION_DONE"}
    for mac in sorted(overridable - set(re.findall(r"PHGMG_[A-Z0-9_]+", sec9))):
        if not mac.startswith("PHGMG__"):
            problems.append("phgmg.h: the configuration macro %s is not in the manual's section 9" % mac)
    count = re.search(r"\((\d+) functions;", index)
    if not count or int(count.group(1)) != len(declared):
        problems.append("phgmg.h: the manual's index says (%s functions; ...), the header declares %d"
                        % (count.group(1) if count else "no count", len(declared)))
    print("docs-check: %d public functions, all in the manual's index" % len(declared)
          if declared <= named else "docs-check: index incomplete")


def check_help(binary):
    src = read("examples/phgmg_cli.c")
    opts = set(re.findall(r'(?:strcmp\([^,()]+,\s*|\b(?:STR|INT|DBL)\()"(--[A-Za-z][A-Za-z0-9-]*)"', src))
    if len(opts) < 20:
        problems.append("examples/phgmg_cli.c: found only %d parsed options; has the parser changed?" % len(opts))
    try:
        out = subprocess.run([binary, "--help"], capture_output=True, text=True, timeout=30)
    except OSError as e:
        problems.append("%s --help: %s" % (binary, e))
        return
    if out.returncode != 0:
        problems.append("%s --help exits with %d" % (binary, out.returncode))
    text = out.stdout
    for o in sorted(opts):
        if not re.search(r"(?<![A-Za-z0-9-])" + re.escape(o) + r"(?![A-Za-z0-9-])", text):
            problems.append("phgmg --help does not name the option %s that the CLI parses" % o)
    print("docs-check: %d options parsed by the CLI, checked against --help" % len(opts))


def check_readme_program(readme):
    m = re.search(r"```c\n(.*?)```", readme, re.S)
    if not m:
        problems.append("README.md: no C block")
        return
    d = os.path.join(ROOT, "build", "docs")
    os.makedirs(d, exist_ok=True)
    src, exe = os.path.join(d, "readme_quickstart.c"), os.path.join(d, "readme_quickstart")
    with open(src, "w", encoding="utf-8") as f:
        f.write(m.group(1))
    cmd = [CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wshadow", "-O0",
           "-I", ROOT, "-o", exe, src, "-lm"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        problems.append("README.md: the first C block does not compile:\n" + r.stderr[-2000:])
        return
    r = subprocess.run([exe], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        problems.append("README.md: the first C block exits with %d: %s" % (r.returncode, r.stdout + r.stderr))
        return
    print("docs-check: README's first C block compiles and runs: " + r.stdout.strip())


DEFAULTS_C = r"""
#define PHGMG_IMPLEMENTATION
#include "phgmg.h"
#include <stdio.h>
int main(void) {
  phgmg_reduce_opts o;
  phgmg_reduce_opts_default(&o);
#define I(f) printf(#f " %d\n", (int)o.f);
#define D(f) printf(#f " %.17g\n", o.f);
  D(dt) D(degeneracy_tol) I(qm.rn) D(qm.lambda) I(qm.manifold) I(qm.greedy_window)
  I(select.lambda_mode) D(select.lambda_min) D(select.lambda_max) I(select.per_decade) I(select.folds)
  D(select.rcond) D(select.tolerance) I(select.train_only) I(select.newton_iter)
  I(hyper.on) I(hyper.kind) D(hyper.tol) D(hyper.deim_tol) I(hyper.deim_max) I(hyper.allow_negative)
  return 0;
}
"""
# names the manual's table uses for a default that is an enum or a phrase
WORDS = {"PHGMG_HYPER_ECSW": 0.0, "PHGMG_MANIFOLD_POD": 0.0, "PHGMG_LAMBDA_FIXED": 0.0, "no": 0.0}


def check_defaults(header, binary):
    d = os.path.join(ROOT, "build", "docs")
    os.makedirs(d, exist_ok=True)
    src, exe = os.path.join(d, "opts_defaults.c"), os.path.join(d, "opts_defaults")
    with open(src, "w", encoding="utf-8") as f:
        f.write(DEFAULTS_C)
    r = subprocess.run([CC, "-std=c99", "-O0", "-I", ROOT, "-o", exe, src, "-lm"], capture_output=True, text=True)
    if r.returncode != 0:
        problems.append("phgmg_reduce_opts_default: the query program does not compile:\n" + r.stderr[-1500:])
        return
    got = {}
    for line in subprocess.run([exe], capture_output=True, text=True).stdout.split("\n"):
        if line.strip():
            k, v = line.split()
            got[k] = float(v)
    top = header[: header.index("*/")]
    a = top.find("3.2 phgmg_reduce_opts")
    b = top.find("3.3 ", a)
    table = {}
    for line in top[a:b].split("\n"):
        m = re.match(r"     ([a-z_.]+)\s+(\S+)", line)
        if m:
            table[m.group(1)] = m.group(2)
    for k, v in sorted(got.items()):
        if k not in table:
            problems.append("manual 3.2: no row for phgmg_reduce_opts.%s (default %g)" % (k, v))
            continue
        t = table[k]
        try:
            tv = WORDS[t] if t in WORDS else float(t)
        except ValueError:
            problems.append("manual 3.2: %s's default '%s' is not a value" % (k, t))
            continue
        if tv != v:
            problems.append("manual 3.2 says %s = %s, phgmg_reduce_opts_default gives %.17g" % (k, t, v))
    try:
        text = subprocess.run([binary, "--help"], capture_output=True, text=True, timeout=30).stdout
    except OSError:
        text = ""
    for opt, field, pat in (("--rn", "qm.rn", r"--rn K .*?\(default (\S+?)[,)]"),
                            ("--deim-tol", "hyper.deim_tol", r"--deim-tol T .*?\(default (\S+?)[;,)]"),
                            ("--hyper-tol", "hyper.tol", r"--hyper-tol T .*?\(default (\S+?)[;,)]")):
        m = re.search(pat, text, re.S)
        if not m:
            problems.append("phgmg --help: no default stated for %s" % opt)
        elif float(m.group(1)) != got.get(field):
            problems.append("phgmg --help says %s defaults to %s, the library's default is %.17g"
                            % (opt, m.group(1), got.get(field)))
    print("docs-check: %d defaults of phgmg_reduce_opts agree with the manual's table and --help" % len(got))


RENAME_C = r"""
#include "phgmg.h"
void f(phgmg_reduce_opts *o);
void f(phgmg_reduce_opts *o) {
%s
}
"""


def check_renames(header):
    """The revision history's table of renamed options (old -> new): every
    new name compiles, every old one does not (no silent change of meaning)."""
    a = header.find("   REVISION HISTORY")
    m = re.search(r"Old name -> new name:\n(.*?)\n\s+Unchanged:", header[a:], re.S)
    if a < 0 or not m:
        problems.append("phgmg.h: no table 'Old name -> new name:' in the newest revision history entry")
        return
    pairs = re.findall(r"\b([a-z_]+) -> ([a-z_]+\.[a-z_]+)\b", m.group(1))
    if len(pairs) < 20:
        problems.append("phgmg.h: the rename table has only %d entries" % len(pairs))
        return
    d = os.path.join(ROOT, "build", "docs")
    os.makedirs(d, exist_ok=True)

    def compile_lines(name, lines):
        src = os.path.join(d, name)
        with open(src, "w", encoding="utf-8") as f:
            f.write(RENAME_C % "\n".join(lines))
        r = subprocess.run([CC, "-std=c99", "-fsyntax-only", "-I", ROOT, src], capture_output=True, text=True)
        bad = set(int(n) for n in re.findall(r"%s:(\d+):\d+: error" % re.escape(src), r.stderr))
        first = RENAME_C.split("\n").index("%s") + 1
        return r, [first + k in bad for k in range(len(lines))]

    r, errs = compile_lines("renames_new.c", ["  (void)sizeof(o->%s);" % new for _, new in pairs])
    if r.returncode != 0:
        problems.append("phgmg.h: new option names of the rename table do not compile:\n" + r.stderr[-1500:])
    # (int) makes a struct-valued old name (hyper) an error too
    r, errs = compile_lines("renames_old.c", ["  (void)sizeof((int)o->%s);" % old for old, _ in pairs])
    for (old, new), e in zip(pairs, errs):
        if not e:
            problems.append("phgmg_reduce_opts.%s still compiles (renamed to %s)" % (old, new))
    print("docs-check: %d renamed options: the new names compile, the old ones do not" % len(pairs))


def check_file_names():
    try:
        r = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], capture_output=True, text=True, check=True)
        names = [n for n in r.stdout.split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = [os.path.relpath(os.path.join(dp, f), ROOT) for dp, _, fs in os.walk(ROOT) if ".git" not in dp for f in fs]
    for n in names:
        if any(part.startswith("-") for part in n.split("/")):
            problems.append("tracked file whose name starts with '-': %s" % n)


def linalg_signatures(text):
    """The PHGMG__PRIV signatures (whitespace normalised) at file level in text."""
    sigs, depth, cur = [], 0, None
    for l in text.split("\n"):
        if cur is not None:
            cur += " " + l
        elif depth == 0 and l.startswith("PHGMG__PRIV "):
            cur = l
        if cur is not None and re.search(r"[;{]\s*$", cur):
            sigs.append(" ".join(re.sub(r"\s*[;{]\s*$", "", cur).split()))
            cur = None
        if not l.startswith("#"):
            depth += l.count("{") - l.count("}")
    return sigs


def check_linalg_prototypes(header):
    a = header.find("/* >>linalg (prototypes)")
    b = header.find("/* >>", a + 1)
    c = header.find("/* >>linalg (implementation)")
    if a < 0 or b < 0 or c < 0:
        problems.append("phgmg.h: no >>linalg (prototypes) or >>linalg (implementation) section")
        return
    d = header.find("#endif /* PHGMG_IMPLEMENTATION_DONE */", c)
    proto, defs = linalg_signatures(header[a:b]), linalg_signatures(header[c:d])
    if proto != defs:
        extra = [p for p in proto if p not in defs]
        missing = [p for p in defs if p not in proto]
        what = ("stale: %s; missing: %s" % (extra or "none", missing or "none")
                if extra or missing else "another order")
        problems.append("phgmg.h: >>linalg (prototypes) does not match the private functions "
                        "defined in >>linalg (implementation): %s" % what)
    else:
        print("docs-check: %d prototypes of >>linalg, as defined and in order" % len(proto))


def check_words():
    pat = re.compile(r"\bissues?\s*#?\d+|\bsessions?\b|NUMER[I]CS|STYLE\.md", re.I)
    for path in ("README.md", "phgmg.h", "Makefile"):
        for no, line in enumerate(read(path).split("\n"), 1):
            m = pat.search(line)
            if m:
                problems.append("%s:%d: user-facing text mentions '%s'" % (path, no, m.group(0)))


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "phgmg")
    check_index(read("phgmg.h"))
    check_help(binary)
    check_readme_program(read("README.md"))
    check_defaults(read("phgmg.h"), binary)
    check_renames(read("phgmg.h"))
    check_file_names()
    check_linalg_prototypes(read("phgmg.h"))
    check_words()
    for p in problems:
        print("docs-check: FAIL: " + p)
    print("docs-check: %s" % ("passed" if not problems else "%d problem(s)" % len(problems)))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
