"""One home per formula: each formula below is written once in src/, and everywhere else calls it.

Each pattern below is a formula that has exactly one home; a match anywhere else in src/ fails
with the file, line and the function to call instead. Token-level duplicate finders (pylint's
``duplicate-code``) need 6-8 identical lines and miss these one-to-three-line pastes, which is why
they are listed here by shape.
"""

import ast
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "skyradar"

PATTERNS = {
    "power image: use skyradar.process.power.power_image": re.compile(
        r"np\.(sum|mean)\(\s*np\.abs\([^()]*\)\s*\*\*\s*2\s*,\s*axis=(-1|2)\)"
        r"|\.real\s*\*\*\s*2\s*\+\s*[\w.]*\.imag\s*\*\*\s*2"
    ),
    "bin rounding: use RadarConfig.range_bin / doppler_bin": re.compile(
        r"resolution_m(ps)?\s*\+\s*0\.5|round\([^),]*/\s*[\w.]*resolution_m"
    ),
    "Doppler wrap: use RadarConfig.doppler_bin": re.compile(r"n_doppler\s*//\s*2\s*\)\s*%"),
    "Kalman (I-K)P update: use skyradar.kalman.update": re.compile(
        r"\(np\.eye\([^)]*\)\s*-\s*\w+(\s*@\s*\w+)?\)\s*@"
    ),
    "angle wrap: use skyradar.units.wrap_angle": re.compile(
        r"np\.angle\(\s*np\.exp\(\s*1j\s*\*\s*\([^()]*(\([^()]*\)[^()]*)*\)\s*\)\s*\)"
        r"|\+\s*np\.pi\)\s*%\s*\(?\s*2(\.0)?\s*\*\s*np\.pi\)?\s*-\s*np\.pi"
    ),
    "interval wrap: use skyradar.units.wrap": re.compile(
        r"\+\s*(?!np\.pi\b)([\w.]+)\s*\)\s*%\s*\(\s*2(\.0)?\s*\*\s*\1\s*\)\s*-\s*\1\b"
    ),
}
# (path relative to src/skyradar, pattern key prefix) -> why it may stay.
ALLOWED = {
    ("benchmarks/flight_state.py", "power image"): "the thesis' plain loop, timed as the benchmark baseline",
}
JSON_HOME = "io/json_results.py"


def _json_sanitisers(tree: ast.AST) -> list[int]:
    """Lines of functions that recurse into containers and turn non-finite floats into None."""
    found = []
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef):
            continue
        calls_self = any(
            isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == fn.name
            for n in ast.walk(fn)
        )
        if calls_self and "isfinite" in (text := ast.unparse(fn)) and "return None" in text:
            found.append(fn.lineno)
    return found


def find_pastes(root: Path) -> list[str]:
    """Every place under ``root`` where one of the homed formulas is written again."""
    out = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        text = path.read_text()
        for key, pattern in PATTERNS.items():
            if any(rel == a and key.startswith(p) for a, p in ALLOWED):
                continue
            for m in pattern.finditer(text):
                out.append(f"{rel}:{text.count(chr(10), 0, m.start()) + 1}: {key}")
        if rel != JSON_HOME:
            out += [
                f"{rel}:{line}: JSON sanitiser: use skyradar.io.json_results.jsonable"
                for line in _json_sanitisers(ast.parse(text))
            ]
    return out


def test_no_homed_formula_is_pasted_in_src():
    assert find_pastes(SRC) == []


def test_the_check_finds_each_kind_of_paste(tmp_path):
    (tmp_path / "a.py").write_text(
        "p = np.sum(np.abs(frame) ** 2, axis=-1)\n"
        "k = int(round(r / cfg.range_resolution_m))\n"
        "j = (np.floor(v / cfg.doppler_resolution_mps + 0.5) + cfg.n_doppler // 2) % cfg.n_doppler\n"
        "x, p = x + g @ y, (np.eye(3) - g) @ p\n"
        "d = np.angle(np.exp(1j * (a - b)))\n"
        "e = (a - b + np.pi) % (2 * np.pi) - np.pi\n"
        "v = (v + config.v_lim_mps) % (2.0 * config.v_lim_mps) - config.v_lim_mps\n"
        "def clean(v):\n"
        "    if isinstance(v, dict):\n"
        "        return {k: clean(x) for k, x in v.items()}\n"
        "    return None if not np.isfinite(v) else v\n"
    )
    kinds = [line.split(": ", 1)[1].split(":")[0] for line in find_pastes(tmp_path)]
    assert kinds == [
        "power image",
        "bin rounding",
        "bin rounding",
        "Doppler wrap",
        "Kalman (I-K)P update",
        "angle wrap",
        "angle wrap",
        "interval wrap",
        "JSON sanitiser",
    ], kinds
