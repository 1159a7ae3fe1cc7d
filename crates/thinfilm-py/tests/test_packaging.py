"""The installed package ships type hints and documents every public function."""

import ast
import pathlib

import thinfilm


def test_every_public_function_has_a_docstring_and_a_type_hint():
    stub = pathlib.Path(thinfilm.__file__).with_suffix(".pyi")
    assert stub.exists(), stub
    assert (stub.parent / "py.typed").exists()
    hinted = {node.name for node in ast.parse(stub.read_text()).body if isinstance(node, ast.FunctionDef)}
    for name in thinfilm.__all__:
        assert name in hinted, name
        assert (getattr(thinfilm, name).__doc__ or "").strip(), name
