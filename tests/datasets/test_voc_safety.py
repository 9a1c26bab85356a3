"""VOC XML is parsed with defusedxml: an entity-expansion file is one clear error, not a hang."""

import pytest

from tsrkit.datasets import DatasetError, read_dataset

BOMB = """<?xml version="1.0"?>
<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;">]>
<annotation><filename>&lol2;</filename></annotation>
"""


def test_xml_entities_are_refused(tmp_path):
    (tmp_path / "a.xml").write_text(BOMB)
    with pytest.raises(DatasetError, match="forbidden construct"):
        read_dataset(tmp_path, "voc")
