"""The forward model: strip -> moment integral -> moment -> beam outputs, with the checks,
escalation and withholding that every command and study shares."""
