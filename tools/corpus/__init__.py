"""The blind corpus of robots the drafts are measured on (issue 30): manifests, split, fetching."""
