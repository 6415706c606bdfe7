"""PEP 517 build backend for the Fovea Python client (pyproject.toml).

Builds a wheel of fovea_client/ plus the stubs of the wire contract,
generated here and now from the repository's proto/ files with protoc and
grpc_python_plugin (FOVEA_PROTOC and FOVEA_GRPC_PYTHON_PLUGIN override
where they are looked for; FOVEA_PROTO_DIR the proto folder,
FOVEA_GRPC_PROTO_ROOT the folder holding grpc/health/v1/health.proto).
Needs no package from PyPI: the wheel is a zip written with the standard
library.
"""

import base64
import hashlib
import os
import pathlib
import shutil
import subprocess
import tempfile
import zipfile

NAME = "fovea_client"
DIST = "fovea-client"
VERSION = "0.1.0"
HERE = pathlib.Path(__file__).resolve().parent.parent  # client/python
TAG = "py3-none-any"
REQUIRES = ["grpcio>=1.51", "protobuf>=3.21", "numpy>=1.21"]
SUMMARY = ("Client for Fovea's perception service (fovea.v1.Perception): "
           "attention points, object masks and boxes from RGB-D frames "
           "over gRPC")


def _tool(env, name):
    path = os.environ.get(env) or shutil.which(name)
    if not path:
        raise RuntimeError(
            f"fovea-client build: {name} not found (Debian: "
            f"protobuf-compiler / protobuf-compiler-grpc; or set {env})")
    return path


def _generate(out):
    """The stubs under `out`: fovea/v1/*_pb2(_grpc).py and
    fovea/health/v1/health_pb2.py, with their __init__.py files."""
    protoc = _tool("FOVEA_PROTOC", "protoc")
    plugin = _tool("FOVEA_GRPC_PYTHON_PLUGIN", "grpc_python_plugin")
    proto_dir = pathlib.Path(
        os.environ.get("FOVEA_PROTO_DIR", HERE.parent.parent / "proto"))
    grpc_root = pathlib.Path(
        os.environ.get("FOVEA_GRPC_PROTO_ROOT", "/usr/share/grpc-proto"))
    protos = sorted(str(p.relative_to(proto_dir))
                    for p in (proto_dir / "fovea" / "v1").glob("*.proto"))
    if not protos:
        raise RuntimeError(f"fovea-client build: no .proto in {proto_dir}")
    subprocess.run([protoc, f"--proto_path={proto_dir}",
                    f"--python_out={out}", f"--grpc_python_out={out}",
                    f"--plugin=protoc-gen-grpc_python={plugin}", *protos],
                   check=True, cwd=proto_dir)
    # The health messages only, as fovea.health.v1 (a top-level `grpc`
    # package would shadow grpcio).
    (out / "fovea").mkdir(exist_ok=True)
    subprocess.run([protoc, f"--proto_path={grpc_root / 'grpc'}",
                    f"--python_out={out / 'fovea'}", "health/v1/health.proto"],
                   check=True)
    for package in ("fovea", "fovea/v1", "fovea/health", "fovea/health/v1"):
        (out / package / "__init__.py").touch()


def _metadata():
    lines = ["Metadata-Version: 2.1", f"Name: {DIST}", f"Version: {VERSION}",
             f"Summary: {SUMMARY}", "Requires-Python: >=3.9"]
    lines += [f"Requires-Dist: {r}" for r in REQUIRES]
    return "\n".join(lines) + "\n"


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest())
    return f"{name},sha256={digest.rstrip(b'=').decode()},{len(data)}"


def _write_wheel(directory, files):
    """files: {archive name: bytes}. Returns the wheel's file name."""
    dist_info = f"{NAME}-{VERSION}.dist-info"
    files = dict(files)
    files[f"{dist_info}/METADATA"] = _metadata().encode()
    files[f"{dist_info}/WHEEL"] = (
        "Wheel-Version: 1.0\nGenerator: fovea_build\nRoot-Is-Purelib: true\n"
        f"Tag: {TAG}\n").encode()
    files[f"{dist_info}/top_level.txt"] = b"fovea\nfovea_client\n"
    record = [_record_line(n, d) for n, d in sorted(files.items())]
    record.append(f"{dist_info}/RECORD,,")
    files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel = f"{NAME}-{VERSION}-{TAG}.whl"
    with zipfile.ZipFile(pathlib.Path(directory) / wheel, "w",
                         zipfile.ZIP_DEFLATED) as z:
        for name, data in files.items():
            z.writestr(name, data)
    return wheel


def _package_files():
    files = {}
    for path in sorted((HERE / NAME).rglob("*")):
        if path.is_file() and path.suffix in (".py", ".typed"):
            files[str(path.relative_to(HERE))] = path.read_bytes()
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp)
        _generate(out)
        for path in sorted(out.rglob("*.py")):
            files[str(path.relative_to(out))] = path.read_bytes()
    return files


# PEP 517 hooks.
def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


def build_wheel(wheel_directory, config_settings=None,
                metadata_directory=None):
    return _write_wheel(wheel_directory, _package_files())


def build_editable(wheel_directory, config_settings=None,
                   metadata_directory=None):
    # An editable install is an ordinary one here: the stubs must be
    # generated anyway.
    return build_wheel(wheel_directory, config_settings, metadata_directory)


def prepare_metadata_for_build_wheel(metadata_directory,
                                     config_settings=None):
    dist_info = pathlib.Path(metadata_directory) / f"{NAME}-{VERSION}.dist-info"
    dist_info.mkdir(parents=True, exist_ok=True)
    (dist_info / "METADATA").write_text(_metadata())
    return dist_info.name
