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
import time
import uuid
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

    # fsspec keeps one instance per constructor arguments, and the endpoint and keys come from the
    # environment, not the arguments: without skipping its cache a new endpoint would reuse the old client.
    # Listings are not cached: other workers write the same prefixes, and a stale listing would hide them.
    opts = {"use_listings_cache": False} if protocol_url.split("://")[0] in ("s3", "s3a") else {}
    fs = fsspec.core.url_to_fs(protocol_url, skip_instance_cache=True, **opts)[0]
    if protocol_url == "file://":
        return fs
    from .remote_fs import ResilientFS

    return ResilientFS(fs, os.environ.get("AWS_ENDPOINT_URL") or protocol_url)


def filesystem(url: str) -> tuple[Any, str]:
    """The fsspec filesystem for ``url`` and the path inside it (clients cached per endpoint and keys).

    A remote one retries an unreachable store and fails with one line (tasks/remote_fs.py)."""
    import fsspec

    protocol, path = fsspec.core.split_protocol(url)
    secret = hashlib.sha256(os.environ.get("AWS_SECRET_ACCESS_KEY", "").encode()).hexdigest()[:16]
    env_key = "|".join([*(os.environ.get(k, "") for k in ("AWS_ENDPOINT_URL", "AWS_ACCESS_KEY_ID")), secret])
    fs = _fs_cached(f"{protocol}://" if protocol else "file://", env_key)
    return fs, fs._strip_protocol(url)


# --- the remote mirror of the content store ---------------------------------------------------------

def find_files(url: str) -> dict[str, dict[str, Any]]:
    """Files under ``url`` (local or remote) by path relative to it, with the store's details (size,
    ETag, mtime); nothing when it does not exist."""
    fs, path = filesystem(url)
    path = path.rstrip("/")
    try:
        found = fs.find(path, detail=True)
    except FileNotFoundError:
        return {}
    return {name[len(path):].lstrip("/"): info for name, info in found.items()
            if info.get("type", "file") == "file" and name.startswith(path)}


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
        _place(tmp, local)
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


OUTPUT_POINTER = "react3d-output.json"
"""The pointer object of a published remote output: which prefix holds it, every file's size and sha256."""

VERSIONS_DIR = "v"
"""Key prefix under a remote output that holds one sub-prefix per publication."""


def publish_tree(local: Path, url: str) -> str:
    """Upload a finished local output folder to ``url``; returns the manifest's URL.

    S3 has no atomic rename, so each publication goes under a fresh prefix ``url/v/<id>/`` and the small
    pointer ``url/react3d-output.json`` (the prefix, every file's size and sha256) is written last: a
    reader that follows the pointer (:func:`fetch_output`) sees one whole output or refuses it, never half
    of one. After the pointer lands, publications older than the previous one are removed (a reader that
    read the previous pointer a moment ago can still finish), and so are files of earlier react3d outputs
    outside ``v/``."""
    check_remote_output(url)
    url = url.rstrip("/")
    fs, path = filesystem(url)
    manifest = json.loads((local / "scene.json").read_text(encoding="utf-8"))
    mesh = manifest.get("input_mesh")
    if mesh and not Path(mesh).is_absolute():  # relative to a local folder: meaningless remotely
        manifest["input_mesh"] = str((local / mesh).resolve())
    manifest_bytes = json.dumps(manifest, indent=2).encode()
    if not fs.exists(f"{path}/{OUTPUT_MARKER}"):  # first: a half publication is still known to be react3d's
        fs.pipe_file(f"{path}/{OUTPUT_MARKER}", (local / OUTPUT_MARKER).read_bytes() if (local / OUTPUT_MARKER).is_file() else b"{}")
    previous = _pointer_prefix(fs, path)
    vid = f"{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}-{uuid.uuid4().hex[:8]}"
    prefix = f"{VERSIONS_DIR}/{vid}"
    files = {p.relative_to(local).as_posix(): p for p in sorted(local.rglob("*")) if p.is_file()}
    entries: dict[str, dict[str, Any]] = {}
    for rel, p in files.items():
        if rel != "scene.json":
            entries[rel] = {"size": p.stat().st_size, "sha256": _file_sha256(p)}
    entries["scene.json"] = {"size": len(manifest_bytes), "sha256": hashlib.sha256(manifest_bytes).hexdigest()}
    uploads = [rel for rel in files if rel != "scene.json"]
    if uploads:  # one batched, concurrent upload
        fs.put([str(files[r]) for r in uploads], [f"{path}/{prefix}/{r}" for r in uploads])
    fs.pipe_file(f"{path}/{prefix}/scene.json", manifest_bytes)
    pointer = {"version": 1, "prefix": prefix, "manifest": "scene.json", "files": entries}
    fs.pipe_file(f"{path}/{OUTPUT_POINTER}", json.dumps(pointer, indent=1, sort_keys=True).encode())
    keep = {f"{prefix}/"} | ({f"{previous}/"} if previous else set())
    stale = [f for f in fs.find(path) if (rel := f[len(path):].lstrip("/")) not in (OUTPUT_MARKER, OUTPUT_POINTER)
             and not any(rel.startswith(k) for k in keep)]
    if stale:
        fs.rm(stale)
    return f"{url}/{prefix}/scene.json"


def _file_sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while block := fh.read(1 << 20):
            h.update(block)
    return h.hexdigest()


POINTER_READS = 3  # reads of a pointer that does not parse before it is called unreadable
POINTER_RETRY_S = 0.2


def _pointer_prefix(fs: Any, path: str) -> str | None:
    """The prefix the current pointer names (None: no readable pointer)."""
    try:
        return str(json.loads(fs.cat_file(f"{path}/{OUTPUT_POINTER}"))["prefix"]).strip("/")
    except (FileNotFoundError, ValueError, KeyError, TypeError):
        return None


def read_pointer(url: str) -> dict[str, Any]:
    """The pointer of the remote output ``url``, checked against what the store lists (names and sizes).

    Raises a one-line :class:`InputError` when it is missing (not a react3d output, or its publication
    has not finished), unreadable, or does not match the objects under its prefix."""
    url = url.rstrip("/")
    fs, path = filesystem(url)
    for attempt in range(POINTER_READS):
        try:
            raw = fs.cat_file(f"{path}/{OUTPUT_POINTER}")
        except FileNotFoundError:
            raise InputError(url, f"has no {OUTPUT_POINTER}: not a published react3d output, or its publication "
                                  "has not finished") from None
        try:
            pointer = json.loads(raw)
            prefix = str(pointer["prefix"]).strip("/")
            files = {str(k): {"size": int(v["size"]), "sha256": str(v["sha256"])} for k, v in pointer["files"].items()}
            break
        except (ValueError, KeyError, TypeError, AttributeError):
            # a store whose writes are not atomic (a file-backed S3 server) can be read mid-replacement
            if attempt == POINTER_READS - 1:
                raise InputError(f"{url}/{OUTPUT_POINTER}", "is not a readable react3d output pointer") from None
            time.sleep(POINTER_RETRY_S)
    if not prefix.startswith(f"{VERSIONS_DIR}/") or ".." in prefix.split("/") or \
            any(".." in k.split("/") or k.startswith("/") for k in files) or "scene.json" not in files:
        raise InputError(f"{url}/{OUTPUT_POINTER}", "names files outside its output; refusing it")
    try:
        listed = {f[len(f"{path}/{prefix}"):].lstrip("/"): int(i.get("size", -1))
                  for f, i in fs.find(f"{path}/{prefix}", detail=True).items() if i.get("type", "file") == "file"}
    except FileNotFoundError:
        listed = {}
    for rel, want in sorted(files.items()):
        if rel not in listed:
            raise InputError(f"{url}/{prefix}/{rel}", f"is missing: the output does not match its {OUTPUT_POINTER}")
        if listed[rel] != want["size"]:
            raise InputError(f"{url}/{prefix}/{rel}", f"has {listed[rel]} bytes, its {OUTPUT_POINTER} says "
                                                      f"{want['size']}: the output does not match its pointer")
    extra = sorted(set(listed) - set(files))
    if extra:
        raise InputError(f"{url}/{prefix}/{extra[0]}", f"is not listed in its {OUTPUT_POINTER}: the output does not match its pointer")
    return {"prefix": prefix, "files": files, "sha": hashlib.sha256(raw).hexdigest()}


def output_manifest(out: str) -> str:
    """The manifest (``scene.json``) of a published output: under a local folder, or the URL its pointer names."""
    if not is_remote(out):
        return str(Path(out) / "scene.json")
    return f"{out.rstrip('/')}/{read_pointer(out)['prefix']}/scene.json"


def fetch_output(url: str) -> Path:
    """A verified local copy of the remote output ``url`` (what ``view``, ``export`` and ``evaluate`` read).

    Follows its pointer (:func:`read_pointer`), downloads every file it lists into this machine's cache
    (``<cache>/outputs/<pointer sha>/<name>``, appearing by one rename) and checks each file's sha256
    against it: an output whose objects do not match its pointer is refused with one line, never read."""
    url = url.rstrip("/")
    pointer = read_pointer(url)
    name = url.rsplit("/", 1)[-1] or "output"
    dest = cache_root() / "outputs" / pointer["sha"][:32] / name
    if dest.is_dir():
        return dest
    fs, path = filesystem(url)
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=".tmp", dir=dest.parent))
    try:
        rels = sorted(pointer["files"])
        targets = [tmp / r for r in rels]
        for t in targets:
            t.parent.mkdir(parents=True, exist_ok=True)
        try:
            fs.get([f"{path}/{pointer['prefix']}/{r}" for r in rels], [str(t) for t in targets])
        except FileNotFoundError as exc:
            raise InputError(url, f"an object went away while it was read ({exc}); the output was replaced "
                                  "or removed meanwhile: run the command again") from None
        for r, t in zip(rels, targets):
            if not t.is_file() or _file_sha256(t) != pointer["files"][r]["sha256"]:
                raise InputError(f"{url}/{pointer['prefix']}/{r}",
                                 f"does not match the sha256 in its {OUTPUT_POINTER}: refusing the output")
        _place(tmp, dest)
        return dest
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _place(tmp: Path, dest: Path) -> None:
    """Move a finished download ``tmp`` to ``dest`` in one rename; another thread or process that placed
    the same content there first wins (content-addressed, so either copy is right)."""
    try:
        os.replace(tmp, dest)
    except OSError:
        if not dest.is_dir():
            raise


def fetch_outputs(url: str) -> Path:
    """A verified local copy of one remote output, or of every output directly under a remote prefix (a
    dataset's ``--out``), as one local folder with a sub-folder per scene."""
    url = url.rstrip("/")
    fs, path = filesystem(url)
    if fs.exists(f"{path}/{OUTPUT_POINTER}"):
        return fetch_output(url)
    try:
        subs = sorted(d for d in fs.ls(path, detail=False) if fs.exists(f"{d.rstrip('/')}/{OUTPUT_POINTER}"))
    except FileNotFoundError:
        subs = []
    if not subs:
        raise InputError(url, f"holds no published react3d output (no {OUTPUT_POINTER} there or one level below)")
    h = hashlib.sha256()
    copies = {}
    for d in subs:
        name = d.rstrip("/").rsplit("/", 1)[-1]
        copies[name] = fetch_output(f"{url}/{name}")
        h.update(f"{name}={copies[name]}".encode())
    root = cache_root() / "outputs" / f"set-{h.hexdigest()[:32]}"
    if root.is_dir() and not all((root / n).is_dir() for n in copies):  # a copy it links to was pruned
        shutil.rmtree(root, ignore_errors=True)
    if not root.is_dir():
        tmp = Path(tempfile.mkdtemp(prefix=".set.", suffix=".tmp", dir=root.parent))
        for name, src in copies.items():
            (tmp / name).symlink_to(src, target_is_directory=True)
        try:
            os.replace(tmp, root)
        except OSError:
            shutil.rmtree(tmp, ignore_errors=True)
    return root


def read_text(url: str) -> str:
    """Text of a file given as a local path or any fsspec URL."""
    if not is_remote(url):
        return local_path(url).read_text(encoding="utf-8")
    fs, path = filesystem(url)
    return fs.cat_file(path).decode("utf-8")
