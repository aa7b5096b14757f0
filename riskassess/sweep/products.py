"""The products of a sweep (envelope.json, report.html, report.pdf), one set per store, in the
store's own folder, never over a file the tool did not write.

Where: a store named ``results.sqlite`` (the default, ``sweeps/<case name>/results.sqlite``)
has its products beside it: a folder holds one such store, so one set of products. A store of
any other name, ``DIR/NAME.EXT``, has them in ``DIR/NAME.products/``, so two stores in one
folder never share a report.

Ownership: the store records the SHA-256 of every product it wrote (``products`` in its
``sweep`` table). An existing file at a product's path is replaced only when its content is
one the store wrote; anything else (a user's file, another sweep's report, a hand-edited
report) is refused with a message naming it. The hash of the new content is recorded before
the file is replaced (atomically, through a temporary file), so a sweep killed in between
still owns whichever of the two contents the file holds.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import matplotlib

from riskassess.products import results
from riskassess.products.report.document import render_document, render_pdf
from riskassess.products.plotting import STYLE
from riskassess.products.report.sweep import envelope_section, runs_section, sensitivity_section
from riskassess.products.envelope import envelope, unknown_counts
from riskassess.sweep.store import ResultStore, StoreError

#: The store file name whose products go beside it (the default layout).
DEFAULT_STORE_NAME = "results.sqlite"
PRODUCTS = ("envelope.json", "report.html", "report.pdf")


class ProductConflict(StoreError):
    """A product's path holds a file this store did not write."""


def products_dir(store_path: Path) -> Path:
    """The folder of the products of the store at ``store_path`` (see the module notes).

    Parameters
    ----------
    store_path : Path
        The results store (``.sqlite`` file).
    """
    store_path = Path(store_path)
    if store_path.name == DEFAULT_STORE_NAME:
        return store_path.parent
    return store_path.parent / f"{store_path.stem}.products"


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _owned(store: ResultStore) -> dict[str, list[str]]:
    return store.info().get("products", {})


def check_products(store: ResultStore, names=PRODUCTS) -> Path:
    """The products folder, after checking that no product path holds a file the store did not write.

    Parameters
    ----------
    store : riskassess.sweep.store.ResultStore
        The open store; its ``products`` info holds the hashes of the products it wrote.
    names : sequence of str
        Product file names to check, of :data:`PRODUCTS`.

    Returns
    -------
    Path
        The products folder (:func:`products_dir`).
    """
    return check_products_at(store.path, _owned(store), names)


def check_products_at(store_path: Path, owned: dict[str, list[str]], names=PRODUCTS) -> Path:
    """:func:`check_products` for a store that may not exist yet (``owned`` then empty).

    Parameters
    ----------
    store_path : Path
        The results store (``.sqlite`` file), existing or not.
    owned : dict of str to list of str
        Product name -> SHA-256 hex digests of the contents the store wrote.
    names : sequence of str
        Product file names to check, of :data:`PRODUCTS`.

    Returns
    -------
    Path
        The products folder (:func:`products_dir`).
    """
    folder = products_dir(store_path)
    for name in names:
        path = folder / name
        if path.is_symlink() or (path.exists() and not path.is_file()):
            raise ProductConflict(f"{path}: not a regular file; the sweep's {name} would replace it (move it, or "
                                  f"give another --store)")
        if path.exists() and _sha256(path.read_bytes()) not in owned.get(name, []):
            raise ProductConflict(f"{path}: exists and was not written for the store {store_path}; it is left "
                                  f"as it is (move it, or give another --store)")
    return folder


def write_product(store: ResultStore, name: str, data: bytes) -> Path:
    """Write one product atomically, recording its hash in the store first.

    Parameters
    ----------
    store : riskassess.sweep.store.ResultStore
        The store open for writing.
    name : str
        Product file name, one of :data:`PRODUCTS`.
    data : bytes
        The whole content.

    Returns
    -------
    Path
        The written file.
    """
    folder = check_products(store, (name,))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    owned = _owned(store)
    new = _sha256(data)
    store.set_info("products", {**owned, name: [*owned.get(name, []), new]})
    results.atomic_write_bytes(path, data)
    store.set_info("products", {**owned, name: [new]})
    return path


def write_sweep_products(store: ResultStore, confidence: float = 0.95, reliability: float = 0.9,
                         pdf: bool = True) -> dict:
    """envelope.json and report.html (+ .pdf) in the store's products folder; returns the envelope.

    Parameters
    ----------
    store : riskassess.sweep.store.ResultStore
        The store open for writing.
    confidence : float
        One-sided confidence of the envelope's bound, in (0, 1).
    reliability : float
        Required P(no debris), in (0, 1).
    pdf : bool
        Also write ``report.pdf``.

    Returns
    -------
    dict
        The envelope (:func:`riskassess.products.envelope.envelope`).
    """
    folder = check_products(store, PRODUCTS if pdf else PRODUCTS[:2])
    rows = store.rows()
    info = store.info()
    env = envelope(rows, confidence=confidence, reliability=reliability)
    # allow_nan=False: the envelope never holds a NaN (a "nan" limit once read as a safe limit)
    write_product(store, "envelope.json", (json.dumps(env, indent=2, allow_nan=False) + "\n").encode())
    varied = [a.split(" ", 1)[1].split("=")[0] for a in info.get("arguments", []) if a.startswith("--vary ")]
    with matplotlib.rc_context(STYLE):
        sensitivity = sensitivity_section(rows)
        sections = [envelope_section(rows, env, [k for k in varied if k != env["key"]]),
                    *([sensitivity] if sensitivity else []), runs_section(rows)]
    counts = unknown_counts(rows)
    problems = [f"{n} runs {what}" for what, n in counts.items() if n]
    html = render_document(f"Sweep: {Path(info.get('case_path', '?')).name}",
                           " ".join(info.get("arguments", [])), folder, info.get("created", "-"), problems, sections)
    write_product(store, "report.html", html.encode("utf-8"))
    if pdf:
        write_product(store, "report.pdf", render_pdf(html, folder)[0])
    return env
