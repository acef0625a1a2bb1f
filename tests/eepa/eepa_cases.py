"""Kept only for tests/errors/table_lmp_core.py (another work stream's file), which imports from here:
the EEPA contact cases live in the installed module tsg_cases.eepa_contact. Delete this file when
that table imports from tsg_cases.eepa_contact."""
from tsg_cases.eepa_contact import INPUTS, Eepa

__all__ = ["INPUTS", "Eepa"]
