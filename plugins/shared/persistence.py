"""The learned verifier's scikit-learn model inside a tsrkit model file, safely.

The estimator is serialised with ``skops.io`` (no pickle) into a byte array of the model's
``.npz`` (so :mod:`tsrkit.plugin.models` checksums it like any array) and loaded back with an
explicit
list of trusted types; anything else in the file is refused. skops names its members by
``id()`` of the objects and stamps the time, so the archive is made canonical (members
numbered in schema order, fixed time stamps): the same estimator always gives the same bytes.
"""

from __future__ import annotations

import io
import re
import zipfile
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from tsrkit.api import Model, ModelError

if TYPE_CHECKING:  # skops and scikit-learn load when a model is saved or read, not on import
    from sklearn.ensemble import HistGradientBoostingClassifier

#: The only non-builtin types a verifier model may contain (skops refuses every other one).
TRUSTED_TYPES = ["sklearn.ensemble._hist_gradient_boosting.predictor.TreePredictor"]
ARRAY = "estimator_skops"
#: The array of the verifier's optional second estimator (``box_rank``: does the housing fit).
BOX_ARRAY = "box_estimator_skops"


_ID = re.compile(r'"__id__": (\d+)')


def canonical_skops(data: bytes) -> bytes:
    """``data`` (a skops archive) with object ids renumbered in schema order and fixed member
    time stamps, so that equal estimators give equal bytes."""
    source = zipfile.ZipFile(io.BytesIO(data))
    schema = source.read("schema.json").decode("utf-8")
    number: dict[str, str] = {}
    for match in _ID.finditer(schema):
        number.setdefault(match.group(1), str(len(number) + 1))

    def rename(text: str) -> str:
        text = _ID.sub(lambda m: f'"__id__": {number[m.group(1)]}', text)
        return re.sub(
            r'"file": "(\d+)\.npy"', lambda m: f'"file": "{number[m.group(1)]}.npy"', text
        )

    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_STORED) as target:
        members = {"schema.json": rename(schema).encode("utf-8")}
        for name in source.namelist():
            if name != "schema.json":
                members[f"{number[name.removesuffix('.npy')]}.npy"] = source.read(name)
        for name in sorted(members):
            target.writestr(zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0)), members[name])
    return out.getvalue()


def estimator_arrays(
    estimator: HistGradientBoostingClassifier, name: str = ARRAY
) -> dict[str, np.ndarray]:
    """The model arrays holding ``estimator`` (canonical skops bytes as uint8) as ``name``."""
    import skops.io as sio

    return {name: np.frombuffer(canonical_skops(sio.dumps(estimator)), dtype=np.uint8)}


def load_estimator(
    model: Model, where: str, classes: Sequence | None = (0, 1), name: str = ARRAY
) -> HistGradientBoostingClassifier:
    """The estimator stored by :func:`estimator_arrays` as ``name`` in ``model`` (read from
    ``where``).

    ``classes`` are the labels the estimator must have been fitted on (the verifier's 0 / 1;
    another plugin's own labels; None accepts any).

    Raises
    ------
    ModelError
        No estimator array, bytes skops cannot read, a type outside :data:`TRUSTED_TYPES`, or
        an object that is not a fitted classifier of ``classes``.
    """
    import skops.io as sio
    from sklearn.ensemble import HistGradientBoostingClassifier

    data = model.arrays.get(name)
    if data is None or data.dtype != np.uint8 or data.ndim != 1:
        raise ModelError(f"model {where}: no '{name}' byte array (not a verifier model)")
    try:
        untrusted = [
            t for t in sio.get_untrusted_types(data=data.tobytes()) if t not in TRUSTED_TYPES
        ]
        if untrusted:
            raise ModelError(f"model {where}: refusing untrusted types {untrusted}")
        estimator = sio.loads(data.tobytes(), trusted=TRUSTED_TYPES)
    except ModelError:
        raise
    except Exception as exc:  # skops raises many kinds on damaged bytes
        raise ModelError(
            f"model {where}: unreadable estimator ({type(exc).__name__}: {exc})"
        ) from None
    fitted = list(getattr(estimator, "classes_", []))
    if not isinstance(estimator, HistGradientBoostingClassifier) or (
        fitted != list(classes) if classes is not None else not fitted
    ):
        raise ModelError(f"model {where}: the estimator is not a fitted classifier of {classes}")
    return estimator
