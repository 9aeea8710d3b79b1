"""The paper's claims against the toolkit's numbers: criteria, claims and the report."""
