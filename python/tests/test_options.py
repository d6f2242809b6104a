"""The enhance options on the Python side come from the library's table: the signatures and help of
enhance, enhance_file, batch and enhance_options, the "does not apply to this mode" errors (as the
CLI's), the range checks, and the stub."""

import ast
import inspect
import math
import pathlib
import pydoc
import re
import subprocess
import sys
from collections import defaultdict

import pytest

import vertexflow
from conftest import DATA, STUB_DIR, cli_flags, run_cli

FRONT_ENDS = [vertexflow.enhance, vertexflow.enhance_file, vertexflow.batch, vertexflow.enhance_options]
OPTIONS = vertexflow.ENHANCE_OPTIONS
MODES = {mode["name"]: mode for mode in vertexflow._options.MODE_TABLE}


def test_every_mode_has_options_that_choose_it():
    assert set(MODES) == set(vertexflow.ENHANCE_MODES)
    for name, mode in MODES.items():
        assert vertexflow.enhance_options(has_reference=mode["reference"], **mode["options"]) is not None, name


def test_the_tables_defaults_are_the_librarys():
    library = vertexflow.enhance_options()  # EnhanceOptions{} as reports record it
    assert set(library) == set(OPTIONS)
    for option in OPTIONS.values():
        if option.kind == "indices":
            assert option.default is None and library[option.name] == 0  # no pins; reports give the count
        else:
            assert library[option.name] == option.default, option.name


@pytest.mark.parametrize("function", FRONT_ENDS, ids=lambda f: f.__name__)
def test_help_shows_every_keyword_with_its_default(function):
    signature = inspect.signature(function)
    text = pydoc.render_doc(function, renderer=pydoc.plaintext)
    words = " ".join(function.__doc__.split())
    for option in OPTIONS.values():
        parameter = signature.parameters[option.name]
        assert parameter.kind is inspect.Parameter.KEYWORD_ONLY
        assert repr(parameter.default) == repr(option.default)
        assert str(parameter) in text  # e.g. "lam: float = 1.0" in help()'s signature
        assert f"\n{option.name}: " in function.__doc__ and " ".join(option.help.split()) in words
    assert "**" not in str(signature)


def test_unknown_keywords_raise_type_error():
    V, F = vertexflow.read_mesh(DATA / "sphere_low.off")
    for function, args in [(vertexflow.enhance, (V, F)), (vertexflow.enhance_file, ("a.off", "b.off")),
                           (vertexflow.batch, ("a.off", "out")), (vertexflow.enhance_options, ())]:
        with pytest.raises(TypeError, match="lamda"):
            function(*args, lamda=1.0)


def in_range(option, x) -> bool:
    low = x > option.min if option.min_open else x >= option.min
    high = x < option.max if option.max_open else x <= option.max
    return low and high and math.isfinite(x)


def other_value(option):
    """A value of the option in its range, other than its default."""
    if option.kind == "bool":
        return not option.default
    if option.kind == "choice":
        return next(c for c in option.choices if c != option.default)
    if option.kind == "indices":
        return [0]
    if option.kind == "optional_int":
        return next(x for x in (1, 2, 5) if in_range(option, x))
    candidates = [option.default + 1, option.default - 1] if option.kind == "int" else [
        option.default * 0.5, option.default * 2, option.default + 0.5, 0.5]
    return next(x for x in candidates if x != option.default and in_range(option, x))


@pytest.mark.parametrize("mode", vertexflow.ENHANCE_MODES)
def test_every_keyword_that_does_not_apply_to_a_mode_raises_naming_it(mode, tmp_path):
    V, F = vertexflow.read_mesh(DATA / "sphere_low.off")
    chosen = MODES[mode]
    reference = DATA / "sphere.off" if chosen["reference"] else None
    refused = [o for o in OPTIONS.values() if mode not in o.modes]
    assert refused or mode == "flow"
    for option in refused:
        given = dict(chosen["options"], **{option.name: other_value(option)})
        pattern = rf"(^|\W){option.name}\W.*does not apply"
        with pytest.raises(ValueError, match=pattern):
            vertexflow.enhance(V, F, reference=reference and vertexflow.read_mesh(reference), **given)
        with pytest.raises(ValueError, match=pattern):
            vertexflow.enhance_file(DATA / "sphere_low.off", tmp_path / "out.off", reference=reference, **given)
        with pytest.raises(ValueError, match=pattern):
            vertexflow.batch([DATA / "sphere_low.off"], tmp_path / "batch", reference_dir=reference and DATA, **given)
        with pytest.raises(ValueError, match=pattern):
            vertexflow.enhance_options(has_reference=chosen["reference"], **given)
        # As the CLI refuses it (the table's flag), before reading anything.
        if option.flag:
            result = run_cli("enhance", DATA / "sphere_low.off", tmp_path / "cli.off", *cli_flags(given),
                             *(["--reference", reference] if reference else []), check=False)
            assert result.returncode != 0 and f"{option.flag} does not apply" in result.stderr, result.stderr
    assert not (tmp_path / "out.off").exists() and not (tmp_path / "cli.off").exists()
    # Every option at its default is accepted in every mode (it changes nothing), as by the CLI.
    defaults = {o.name: o.default for o in OPTIONS.values()}
    vertexflow.enhance_options(has_reference=chosen["reference"], **dict(defaults, **chosen["options"]))


def out_of_range(option):
    """Values the option refuses: beyond its bounds, or of another type."""
    if option.kind == "bool":
        return ["yes", 1]
    if option.kind == "choice":
        return ["none-of-them", 1]
    if option.kind == "indices":
        return [[-1], [0.5], "0"]
    values = ["1"] + ([0.5] if option.kind != "float" else [math.nan])
    for bound, step in ((option.min, -1), (option.max, 1)):
        if math.isfinite(bound) and abs(bound) < 1e308:
            values.append(bound if (option.min_open if step < 0 else option.max_open) else bound + step)
    return values


def test_values_out_of_range_or_of_another_type_raise_naming_the_keyword():
    V, F = vertexflow.read_mesh(DATA / "sphere_low.off")
    for option in OPTIONS.values():
        for value in out_of_range(option):
            with pytest.raises(ValueError, match=rf"^{option.name}\b"):
                vertexflow.enhance_options(**{option.name: value})
            with pytest.raises(ValueError, match=rf"^{option.name}\b"):
                vertexflow.enhance(V, F, **{option.name: value})


# --- the stub -----------------------------------------------------------------------------------------


def built_stub() -> pathlib.Path:
    return pathlib.Path(vertexflow.__file__).with_name("__init__.pyi")


def test_stub_is_what_the_generator_writes_from_the_table():
    generated = subprocess.run([sys.executable, STUB_DIR / "generate_stub.py", STUB_DIR / "vertexflow.pyi.in", "-"],
                               capture_output=True, text=True, check=True).stdout
    assert generated == built_stub().read_text()


def stub_functions():
    tree = ast.parse(built_stub().read_text())
    functions = defaultdict(list)
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            functions[node.name].append(node)
    return tree, functions


def test_stub_lists_every_public_name():
    tree, functions = stub_functions()
    public = {n: getattr(vertexflow, n) for n in dir(vertexflow) if not n.startswith("_")}
    classes = {n for n, v in public.items() if isinstance(v, type)}
    assert {n for n, v in public.items() if callable(v)} - classes == set(functions)
    assert {n.name for n in tree.body if isinstance(n, ast.ClassDef)} == classes
    constants = {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    assert constants >= {n for n, v in public.items() if not callable(v) and not inspect.ismodule(v)}


def test_stub_has_every_option_with_the_tables_default():
    _, functions = stub_functions()
    faces = vertexflow._options.FACES_OPTION
    # Overloads: faces unchanged and changed, without and with attributes, and any (a bool, a dict or None).
    assert len(functions["enhance"]) == 5
    for name in ("enhance", "enhance_file", "batch", "enhance_options"):
        runtime = [p for p in inspect.signature(getattr(vertexflow, name)).parameters.values()]
        for node in functions[name]:
            arguments = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
            assert [a.arg for a in arguments] == [p.name for p in runtime], name
            defaults = dict(zip((a.arg for a in node.args.kwonlyargs), node.args.kw_defaults))
            for option in OPTIONS.values():
                if defaults[option.name] is None:  # enhance's overload with the faces changed
                    assert name == "enhance" and option.name == faces
                    assert ast.unparse(node.returns).count("npt.NDArray") == 2
                else:
                    assert ast.literal_eval(defaults[option.name]) == option.default, (name, option.name)


def test_stub_has_the_compiled_functions_defaults():
    # pybind11 writes each signature, defaults included, as the docstring's first line.
    _, functions = stub_functions()
    for name, nodes in functions.items():
        function = getattr(vertexflow, name)
        if hasattr(function, "__signature__"):
            continue  # the option functions, above
        first = function.__doc__.splitlines()[0]
        compiled = ast.parse("def " + re.sub(r" -> .*$", "", first) + ": pass").body[0].args
        runtime = {a.arg: ast.unparse(d) for a, d in zip(compiled.kwonlyargs, compiled.kw_defaults) if d is not None}
        # Overloads may leave a default out (read_mesh's comments: Literal[True]); together they have all.
        stub = {a.arg: d for node in nodes for a, d in zip(node.args.kwonlyargs, node.args.kw_defaults) if d}
        assert set(stub) == set(runtime), name
        for keyword, default in stub.items():
            assert ast.literal_eval(default) == ast.literal_eval(runtime[keyword]), (name, keyword)
