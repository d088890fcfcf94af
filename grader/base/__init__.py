"""The bottom layer every stage stands on: errors said to users, files written whole, inputs read within
bounds (CSV, YAML), the cache's entries, the package's own folders, the heap while grading."""
