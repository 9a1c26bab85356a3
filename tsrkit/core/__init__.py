"""The ground floor: plain types, records, geometry, metric results, errors, file reading,
image reading and atomic, input-safe writes. It imports no other room of tsrkit."""

__all__: list[str] = []
