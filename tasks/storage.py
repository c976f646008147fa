"""Storage every worker can reach: the content store, Prefect's result records and published outputs,
chosen by one URL (``REACT3D_STORE``) and reached through fsspec.

``REACT3D_STORE`` may be

- unset: one machine; the store is the local folder ``REACT3D_CACHE`` (default ``~/.cache/react3d``);
- a path or ``file://`` URL (NFS, any shared mount): the store *is* that folder on every worker (it may
  be mounted at a different path on each one: handles and records hold paths relative to it);
- a remote URL (``s3://bucket/prefix`` on AWS or any S3-compatible server: endpoint and keys from the
  standard ``AWS_ENDPOINT_URL`` / ``AWS_ACCESS_KEY_ID`` / ``AWS_SECRET_ACCESS_KEY``): each worker keeps a
  local mirror in ``REACT3D_CACHE``; every object and sealed store folder is uploaded when it is made and
  downloaded (then verified against its sha256 / seal) when a worker that lacks it needs it.

Stages keep working on local files (meshes, USD, npz), so the remote store is a write-through mirror,
not a virtual filesystem under the core.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any

from pydantic_settings import BaseSettings, SettingsConfigDict

from react3d_core.atomic import OUTPUT_MARKER
from react3d_core.errors import InputError

RESULTS_DIR = "prefect-results"
"""Sub-folder (or key prefix) of the store that holds Prefect's result records."""

RESULT_BLOCK = "react3d-results"
"""Name of the ``remote-file-system`` block that points Prefect's result storage at a remote store."""


class StorageSettings(BaseSettings):
    """Where the shared store lives; read from the environment at each call (workers set it per job)."""

    model_config = SettingsConfigDict(env_prefix="REACT3D_", extra="ignore")

    store: str | None = None
    """URL of the store every worker reaches: a path, ``file://...``, ``s3://bucket/prefix`` (unset: local only)."""

    cache: str | None = None
    """Local folder: the store itself when ``store`` is unset, else this worker's mirror of a remote store."""


def settings() -> StorageSettings:
    return StorageSettings()


def is_remote(url: str | os.PathLike[str] | None) -> bool:
    """Whether ``url`` names a non-local filesystem (``s3://``, ``gcs://``, ...), i.e. needs fsspec."""
    if url is None:
        return False
    s = str(url)
    return "://" in s and not s.startswith("file://")


def local_path(url: str | os.PathLike[str]) -> Path:
    """A path or ``file://`` URL as a local path."""
    s = str(url)
    return Path(s[len("file://"):] if s.startswith("file://") else s)


def cache_root() -> Path:
    """The local root of the store on this worker (the shared folder itself, or the remote's mirror)."""
    st = settings()
    if st.store and not is_remote(st.store):
        return local_path(st.store)
    if st.cache:
        return Path(st.cache)
    return Path.home() / ".cache" / "react3d"


def remote_root() -> str | None:
    """The remote store URL without a trailing slash, or None when the store is local."""
    st = settings()
    return st.store.rstrip("/") if st.store and is_remote(st.store) else None


@lru_cache(maxsize=8)
def _fs_cached(protocol_url: str, env_key: str) -> Any:  # noqa: ARG001 - env_key: new credentials, new client
    import fsspec

    return fsspec.core.url_to_fs(protocol_url)[0]


def filesystem(url: str) -> tuple[Any, str]:
    """The fsspec filesystem for ``url`` and the path inside it (clients cached per endpoint)."""
    import fsspec

    protocol, path = fsspec.core.split_protocol(url)
    env_key = "|".join(os.environ.get(k, "") for k in ("AWS_ENDPOINT_URL", "AWS_ACCESS_KEY_ID"))
    fs = _fs_cached(f"{protocol}://" if protocol else "file://", env_key)
    return fs, fs._strip_protocol(url)


# --- the remote mirror of the content store ---------------------------------------------------------

def push_file(local: Path, rel: str) -> None:
    """Upload one store file (``rel`` under the store root) unless the remote already has it, same size."""
    root = remote_root()
    if root is None:
        return
    fs, path = filesystem(f"{root}/{rel}")
    try:
        if fs.info(path)["size"] == local.stat().st_size:
            return
    except FileNotFoundError:
        pass
    fs.put_file(str(local), path)


def pull_file(rel: str, local: Path) -> bool:
    """Download one store file into the mirror (atomic rename); False when the remote lacks it too."""
    root = remote_root()
    if root is None:
        return False
    fs, path = filesystem(f"{root}/{rel}")
    local.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{local.name}.", suffix=".tmp", dir=local.parent)
    os.close(fd)
    try:
        fs.get_file(path, tmp)
        os.replace(tmp, local)
        return True
    except FileNotFoundError:
        return False
    finally:
        Path(tmp).unlink(missing_ok=True)


def push_dir(local: Path, rel: str, seal: Path | None = None) -> None:
    """Upload a sealed store folder, its seal last (a folder on the remote counts only with its seal)."""
    root = remote_root()
    if root is None:
        return
    fs, path = filesystem(f"{root}/{rel}")
    if seal is not None and fs.exists(f"{path}{seal.name[len(local.name):]}"):
        return  # folders are named by content and sealed last: this one is complete already
    files = [p for p in sorted(local.rglob("*")) if p.is_file()]
    if files:  # one batched, concurrent upload (an export folder holds ~1000 collision pieces)
        fs.put([str(p) for p in files], [f"{path}/{p.relative_to(local).as_posix()}" for p in files])
    if seal is not None:
        push_file(seal, f"{rel}{seal.name[len(local.name):]}")


def pull_dir(rel: str, local: Path, seal_suffix: str) -> bool:
    """Download a store folder and its seal into the mirror (the folder appears by one rename)."""
    root = remote_root()
    if root is None:
        return False
    fs, path = filesystem(f"{root}/{rel}")
    seal_local = local.with_name(local.name + seal_suffix)
    if not pull_file(rel + seal_suffix, seal_local):
        return False
    local.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{local.name}.", suffix=".tmp", dir=local.parent))
    try:
        files = [f for f in fs.find(path) if not f.endswith("/")]
        targets = [tmp / f[len(path):].lstrip("/") for f in files]
        for t in targets:
            t.parent.mkdir(parents=True, exist_ok=True)
        if files:  # one batched, concurrent download
            fs.get(files, [str(t) for t in targets])
        try:
            os.replace(tmp, local)
        except OSError:  # another thread or process placed it first
            if not local.is_dir():
                raise
        return True
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# --- Prefect result storage at the same place --------------------------------------------------------

def result_storage_env(store: str | None) -> dict[str, str]:
    """Prefect settings that keep result records beside the store ``store``.

    A local/shared store keeps them in ``<store>/prefect-results``; a remote one in the
    ``remote-file-system/react3d-results`` block (created by :func:`ensure_result_block`). Prefect reads
    its settings when it is imported: a worker must have these in its environment (or the deployment's
    job variables), which ``deployments/local_cluster.py`` and docs/orchestration.md do."""
    if not store:
        return {}
    if is_remote(store):
        return {"PREFECT_RESULTS_DEFAULT_STORAGE_BLOCK": f"remote-file-system/{RESULT_BLOCK}"}
    return {"PREFECT_LOCAL_STORAGE_PATH": str(local_path(store) / RESULTS_DIR)}


def configure_result_storage() -> None:
    """Apply :func:`result_storage_env` for ``REACT3D_STORE`` (before ``import prefect``; user values win)."""
    for k, v in result_storage_env(settings().store).items():
        os.environ.setdefault(k, v)


def ensure_result_block() -> str | None:
    """Save the ``remote-file-system`` block for a remote store on the current Prefect server; its slug.

    The block holds the URL only: credentials and endpoint stay in each worker's environment."""
    root = remote_root()
    if root is None:
        return None
    from prefect.filesystems import RemoteFileSystem

    RemoteFileSystem(basepath=f"{root}/{RESULTS_DIR}").save(RESULT_BLOCK, overwrite=True)
    return f"remote-file-system/{RESULT_BLOCK}"


# --- published outputs at a URL ------------------------------------------------------------------------

def staging_dir(url: str) -> Path:
    """The local folder a scene for the remote output ``url`` is built in before upload."""
    h = hashlib.sha256(url.rstrip("/").encode()).hexdigest()[:16]
    return cache_root() / "publish" / h / Path(url.rstrip("/")).name


def check_remote_output(url: str) -> None:
    """Refuse a remote output prefix that holds files react3d did not publish (one-line InputError)."""
    fs, path = filesystem(url.rstrip("/"))
    try:
        names = fs.ls(path, detail=False)
    except FileNotFoundError:
        return
    if names and not fs.exists(f"{path}/{OUTPUT_MARKER}"):
        raise InputError(url, "holds files that react3d did not write; choose a new --out location")


def publish_tree(local: Path, url: str) -> str:
    """Upload a finished local output folder to ``url``; returns the manifest's URL.

    S3 has no atomic rename, so the manifest (``scene.json``) is uploaded last: a reader that sees it
    sees the whole scene. Files of an earlier react3d output that the new one lacks are removed."""
    check_remote_output(url)
    url = url.rstrip("/")
    fs, path = filesystem(url)
    manifest = json.loads((local / "scene.json").read_text(encoding="utf-8"))
    mesh = manifest.get("input_mesh")
    if mesh and not Path(mesh).is_absolute():  # relative to a local folder: meaningless remotely
        manifest["input_mesh"] = str((local / mesh).resolve())
    try:
        old = {f[len(path):].lstrip("/") for f in fs.find(path)}
    except FileNotFoundError:
        old = set()
    new: set[str] = set()
    if fs.exists(f"{path}/scene.json"):  # readers must not see the old manifest beside new files
        fs.rm_file(f"{path}/scene.json")
    for p in sorted(local.rglob("*")):
        rel = p.relative_to(local).as_posix()
        if p.is_file() and rel != "scene.json":
            fs.put_file(str(p), f"{path}/{rel}")
            new.add(rel)
    for rel in sorted(old - new - {"scene.json"}):
        fs.rm_file(f"{path}/{rel}")
    fs.pipe_file(f"{path}/scene.json", json.dumps(manifest, indent=2).encode())
    return f"{url}/scene.json"


def read_text(url: str) -> str:
    """Text of a file given as a local path or any fsspec URL."""
    if not is_remote(url):
        return local_path(url).read_text(encoding="utf-8")
    fs, path = filesystem(url)
    return fs.cat_file(path).decode("utf-8")
