;;; driver.el --- drive Emacs's eglot headless against bt-lsp -*- lexical-binding: t -*-

;; Usage: BT_LSP_SERVER="python<TAB>-m<TAB>bt_lsp<TAB>serve" \
;;          emacs --batch -Q -l driver.el FILE.xml
;;
;; Opens FILE.xml as a user does (nxml-mode), connects eglot to the server, and does what a
;; user does: waits for the Flymake diagnostics, asks for the hover on the first bad name,
;; and applies the preferred quick fix through `eglot-code-actions' (the action picked from
;; its completing-read prompt, whose default is the preferred one).  Each result is printed
;; as a line "BTLSP-E2E {json}"; any error exits with status 1.

(dolist (dir (file-expand-wildcards "/usr/share/emacs/site-lisp/elpa/*"))
  (when (file-directory-p dir)
    (add-to-list 'load-path dir)))
(require 'cl-lib)
(require 'json)
(require 'eglot)

(defun btlsp-emit (event data)
  (princ (format "BTLSP-E2E %s\n"
                 (json-encode `((event . ,event) (data . ,data))))))

(defun btlsp-wait (what pred &optional seconds)
  "Wait (serving the server's messages) until PRED is non-nil; its value."
  (let ((deadline (+ (float-time) (or seconds 30)))
        (found nil))
    (while (and (not (setq found (funcall pred))) (< (float-time) deadline))
      (accept-process-output nil 0.05))
    (or found (error "Timed out waiting for %s" what))))

(defun btlsp-diagnostic (diag)
  "DIAG (a Flymake diagnostic) as where the user sees it: 0-based line, and columns in
characters, as Emacs counts them."
  (let* ((beg (flymake-diagnostic-beg diag))
         (end (flymake-diagnostic-end diag))
         (lsp (cdr (assoc 'eglot-lsp-diag (eglot--diag-data diag)))))
    (save-excursion
      (goto-char beg)
      `((line . ,(1- (line-number-at-pos beg t)))
        (col . ,(- beg (line-beginning-position)))
        (end_line . ,(1- (line-number-at-pos end t)))
        (end_col . ,(progn (goto-char end) (- end (line-beginning-position))))
        (text . ,(buffer-substring-no-properties beg end))
        (code . ,(plist-get lsp :code))
        (message . ,(flymake-diagnostic-text diag))))))

(defun btlsp-run (file server)
  (find-file file)
  (unless (derived-mode-p 'nxml-mode)
    (error "%s opened in %s, not nxml-mode" file major-mode))
  (eglot--connect '(nxml-mode) (cons 'transient (file-name-directory file))
                  'eglot-lsp-server server "xml")
  (btlsp-wait "eglot to manage the buffer" (lambda () eglot--managed-mode))
  (let ((diags (btlsp-wait "the diagnostics"
                           (lambda ()
                             (flymake-start)
                             (flymake-diagnostics)))))
    (setq diags (sort diags (lambda (a b) (< (flymake-diagnostic-beg a)
                                             (flymake-diagnostic-beg b)))))
    (btlsp-emit "diagnostics" (vconcat (mapcar #'btlsp-diagnostic diags)))
    (btlsp-emit "capabilities"
                `((hover_formats . ,(plist-get
                                     (plist-get (plist-get (eglot-client-capabilities
                                                            (eglot-current-server))
                                                           :textDocument)
                                                :hover)
                                     :contentFormat))))
    ;; The hover, inside the first bad name.
    (let ((first (car diags)))
      (goto-char (1+ (flymake-diagnostic-beg first)))
      (let* ((hover (jsonrpc-request (eglot--current-server-or-lose)
                                     :textDocument/hover
                                     (eglot--TextDocumentPositionParams)))
             (contents (plist-get hover :contents)))
        (btlsp-emit "hover" `((kind . ,(plist-get contents :kind))
                              (value . ,(plist-get contents :value))
                              (shown . ,(eglot--hover-info contents)))))
      ;; The quick fix, as M-x eglot-code-actions with the cursor on the name: the
      ;; prompt's default is the preferred action, which the user accepts with RET.
      (let ((tick (buffer-chars-modified-tick))
            (offered nil)
            (last-nonmenu-event 13))
        (cl-letf (((symbol-function 'completing-read)
                   (lambda (_prompt collection &optional _pred _req _init _hist def &rest _)
                     (setq offered (mapcar #'car collection))
                     (if (consp def) (car def) def))))
          (eglot-code-actions (flymake-diagnostic-beg first) (flymake-diagnostic-end first)
                              nil t))
        (btlsp-wait "the fix to change the buffer"
                    (lambda () (/= tick (buffer-chars-modified-tick))))
        (btlsp-emit "fix" `((offered . ,(vconcat offered))
                            (text . ,(buffer-substring-no-properties
                                      (point-min) (point-max)))))))
    (eglot-shutdown (eglot-current-server))))

(let ((file (expand-file-name (car command-line-args-left)))
      (server (split-string (or (getenv "BT_LSP_SERVER") "bt-lsp\tserve") "\t")))
  (setq command-line-args-left nil)
  (condition-case err
      (progn (btlsp-run file server)
             (kill-emacs 0))
    (error
     (btlsp-emit "error" (error-message-string err))
     (kill-emacs 1))))
