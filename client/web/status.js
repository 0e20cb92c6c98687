// Where the page says what is going on: the status line beside the controls
// (the connection), and the banner over the view for what the user should
// read (server errors, a bad address), until dismissed or a new session starts.
const $ = (id) => document.getElementById(id);

export function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

export function showBanner(text) {
  $('banner-text').textContent = text;
  $('banner').hidden = false;
}

$('banner-close').addEventListener('click', () => { $('banner').hidden = true; });
