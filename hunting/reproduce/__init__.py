"""Thesis reproductions: each chapter's tables and figures, checked against the thesis values."""
