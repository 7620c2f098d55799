#!/usr/bin/env bash
# Compacts a study's committed runs' records (folders saved by save_run_records.sh) into byte-stable
# archives, runs-records.tar.gz, that `report --records` reads as it reads the folders:
#   bash scripts/compact_records.sh experiments/STUDY/records
# A folder that holds runs' folders gets one archive of all its subfolders; otherwise each subfolder
# that holds runs' folders (a compare folder's saved runs) gets its own. Files beside them stay as they
# are. The folders are removed only once their archive lists every file they held.
# Read an archive by hand with: tar xzf .../runs-records.tar.gz -C <somewhere>
set -euo pipefail
ROOT=${1:?give a study records folder, e.g. experiments/pixels-eval/records}

holds_runs() { compgen -G "$1/*/config.json" > /dev/null; }

compact() {  # compact FOLDER: every subfolder of FOLDER into FOLDER/runs-records.tar.gz
  local folder=$1 archive=$1/runs-records.tar.gz
  [ -e "$archive" ] && { echo "$archive exists: not overwritten" >&2; return 1; }
  local subfolders
  subfolders=$(cd "$folder" && find . -mindepth 1 -maxdepth 1 -type d -printf '%P\n' | sort)
  (cd "$folder" && tar --sort=name --mtime=@0 --owner=0 --group=0 --numeric-owner -cf - $subfolders) \
    | gzip -n > "$archive.tmp"
  local want have
  want=$(cd "$folder" && find $subfolders -type f | sort)
  have=$(tar tzf "$archive.tmp" | grep -v '/$' | sort)
  if [ "$want" != "$have" ]; then
    echo "$archive.tmp does not list every file of $folder: nothing removed" >&2
    return 1
  fi
  mv "$archive.tmp" "$archive"
  (cd "$folder" && rm -r $subfolders)
  echo "$archive: $(echo "$want" | wc -l) files"
}

shopt -s nullglob
found=0
if holds_runs "$ROOT"; then
  compact "$ROOT"; found=1
else
  for sub in "$ROOT"/*/; do
    if holds_runs "${sub%/}"; then compact "${sub%/}"; found=1; fi
  done
fi
[ "$found" = 1 ] || echo "$ROOT holds no runs' records folders: nothing to compact"
