"""Hub dataset-card templates shipped with the package."""

from importlib import resources


def card_template(name: str = "mtdagger_card.md") -> str:
    """Returns the text of a dataset-card template shipped in this folder."""
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")
